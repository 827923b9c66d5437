#!/usr/bin/env bash
# A 60 fps shot between captured poses, morphed in time by the ingested pose-to-pose
# flows and shown at the nearest pose instead, scored against the stage's true walker at
# each frame's instant (issue 24's measurement, on a capture of any seed): the small
# preset's poses 0-4, cycles repeating exactly, one light per condition, uniform light, a
# still camera between the grid's views, no backdrop or shadow; 8 frames of 4 pose steps.
# Prints the walker's PSNR at the half-way frames (1, 3, 5, 7) and at the poses' instants.
# Usage: benches/time_between_poses.sh WORKDIR SEED [FRF] [STAGE_FRF]
#   FRF ingests and scores (default target/release/frf); STAGE_FRF films (default FRF),
#   so that two builds can be compared on one capture. Extra ingest flags: INGEST_FLAGS.
#   ORACLE=1 scores the oracle field with the true pose-to-pose flows instead (`frf stage
#   field --pose-flow`): what the shot would gain with a perfect ingest.
set -euo pipefail
work=$1
seed=$2
frf=${3:-target/release/frf}
stage_frf=${4:-$frf}
mkdir -p "$work"
cap="$work/cap"
[ -f "$cap/capture.toml" ] || "$stage_frf" stage --preset small --poses 0..5 --seed "$seed" \
  --perturbation 0 --lights-per-axis 1 --out "$cap" > /dev/null
field="$work/field.frf"
rm -f "$field"
rm -f "$work/ingest.json"
if [ -n "${ORACLE:-}" ]; then
  "$frf" stage field --capture "$cap" --out "$field" --pose-flow --no-shadows > /dev/null
else
  # shellcheck disable=SC2086
  "$frf" ingest "$cap" --out "$field" --pose-flow --no-shadows ${INGEST_FLAGS:-} \
    --report "$work/ingest.json" > /dev/null
fi
for how in flow nearest; do
  cat > "$work/$how.toml" <<TOML
field = "field.frf"
[time]
start = 0.0
end = 0.1333
fps = 60.0
interpolate = "$how"
[output]
size = [160, 224]
[lighting]
env = "uniform"
[camera]
[[camera.key]]
time = 0.0
position = [0.6, 1.3, 3.1]
look_at = [0.0, 0.9, 0.0]
fov_deg = 40.0
[composite]
backdrop = "none"
shadow = "none"
TOML
  "$frf" eval "$work/$how.toml" --capture "$cap" --frames 8 --lights 256 --json \
    > "$work/$how.json" 2> "$work/$how.log"
done
python3 - "$work" <<'PY'
import json, os, sys
work = sys.argv[1]
if os.path.exists(f"{work}/ingest.json"):
    ingest = json.load(open(f"{work}/ingest.json"))
    print(f"pose-to-pose flow EPE {ingest['pose_flow_epe']:.3f} px of {ingest['pose_flow_motion']:.3f} px true motion")
else:
    print("oracle field: the true pose-to-pose flows")
def walker(how):
    r = json.load(open(f"{work}/{how}.json"))
    return [f["psnr_subject"] for f in r["frames"]]
flow, nearest = walker("flow"), walker("nearest")
half = [1, 3, 5, 7]
at = [0, 2, 4, 6]
mean = lambda v, i: sum(v[k] for k in i) / len(i)
print(f"half-way frames: flow {mean(flow, half):.2f} dB, nearest {mean(nearest, half):.2f} dB, gain {mean(flow, half) - mean(nearest, half):+.2f} dB")
print(f"at the poses' instants: flow {mean(flow, at):.2f} dB, nearest {mean(nearest, at):.2f} dB")
PY
