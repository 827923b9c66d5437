#!/usr/bin/env bash
# Issue 24's first measurement: how much a frame half-way between two captured poses loses
# when it shows the nearest pose, and what a cross-fade and a flow morph of the two
# neighbouring poses' renders (flows computed on the renders) give back; against the
# stage's true walker at that instant. Tiny preset, cycles repeating exactly, oracle field
# of poses 0-6, a static camera at a novel view, uniform light, a 60 fps shot.
# Needs python3 with numpy and OpenEXR (pip install numpy OpenEXR imageio).
# Usage: benches/time_interp/run.sh [WORKDIR] [FRF]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
work=${1:-/tmp/time_interp}
frf=${2:-target/release/frf}
mkdir -p "$work"
[ -d "$work/cap" ] || $frf stage --preset tiny --poses 0..7 --perturbation 0 --lights-per-axis 1 --out "$work/cap"
[ -f "$work/oracle.frf" ] || $frf stage field --capture "$work/cap" --out "$work/oracle.frf" --shadow-texels 32
cat > "$work/s60.toml" <<TOML
field = "oracle.frf"
[time]
start = 0.0
end = 0.2
fps = 60.0
[output]
size = [64, 90]
[lighting]
env = "uniform"
[camera]
[[camera.key]]
time = 0.0
position = [0.0, 1.2, 3.2]
look_at = [0.0, 0.9, 0.0]
fov_deg = 40.0
[composite]
backdrop = "none"
shadow = "none"
TOML
$frf eval "$work/s60.toml" --capture "$work/cap" --frames 12 --cpu
$frf eval "$work/s60.toml" --capture "$work/cap" --frames 12 --cpu --truth-at pose | tail -1
rm -rf "$work/r60"
$frf render "$work/s60.toml" --layers --cpu --out "$work/r60" > /dev/null 2>&1
for i in 1 2 3 4 5 6 7 9; do
  t=$(python3 -c "print($i/60)")
  $frf stage truth --capture "$work/cap" --time "$t" --eye 0,1.2,3.2 --look-at 0,0.9,0 \
    --fov 40 --size 64x90 --env uniform --out "$work/r60/truth_$i.exr" > /dev/null
done
for i in 1 3 5 7 9; do
  a=$(printf "%04d" $((i - 1))); b=$(printf "%04d" $((i + 1)))
  $frf flow "$work/r60/frame_$a.png" "$work/r60/frame_$b.png" --out "$work/r60/f_$i.flo" > /dev/null
  $frf flow "$work/r60/frame_$b.png" "$work/r60/frame_$a.png" --out "$work/r60/g_$i.flo" > /dev/null
done
python3 "$here/experiment.py" "$work/r60"
