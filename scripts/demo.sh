#!/usr/bin/env bash
# The demo, end to end on built-in data, in about ten minutes on two cores (build
# included): the virtual light stage films the walker for the shot of scenes/demo.toml
# only (every third pose of the walk cycle, the views its camera reaches and a ring for
# the visual hull, 96x136 pixels), ingest turns the capture into a flowed reflectance
# field with the flow between consecutive poses (each step's error against the stage's
# truth), `frf render scenes/demo.toml` draws the shot at 30 fps, three frames a pose,
# morphed in time between them (the walker crossing the forest on a path, its walk
# advancing with the distance it covers, the camera following it, relit by the forest
# shipped in assets/envmaps, its shadow on the ground, composited over the environment),
# and `frf eval` scores frames of the shot against their true composites, each against
# the walker where and when the scene places it. Output in demo-out/
# (every step resumes: a rerun continues an interrupted one); demo-out/report.txt holds
# the error and the time of each step.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
chmod 700 "$XDG_RUNTIME_DIR"
out=demo-out
scene=scenes/demo.toml
mkdir -p "$out"
times="$out/times.tsv"
: > "$times"

# step NAME COMMAND...: runs COMMAND, its output shown and kept in $out/NAME.log, and
# its wall time recorded.
step() {
  local name=$1
  shift
  local t0
  t0=$(date +%s.%N)
  "$@" 2>&1 | tee "$out/$name.log"
  awk -v a="$t0" -v b="$(date +%s.%N)" -v n="$name" 'BEGIN { printf "%s\t%.1f\n", n, b - a }' >> "$times"
}

step build cargo build --release --quiet
frf=./target/release/frf
step stage $frf stage --preset small --size 96x136 --lights-per-axis 2 --for "$scene" \
  --poses 0,3,6,9,12,15,18,21,24,27 --out "$out/capture"
step ingest $frf ingest "$out/capture" --for "$scene" --flow-preset fast --pose-flow \
  --out "$out/walker.frf" --report "$out/ingest_report.json"
step plan $frf render "$scene" --field "$out/walker.frf" --plan
step render $frf render "$scene" --field "$out/walker.frf" --out "$out/shot" --overwrite
step eval $frf eval "$scene" --field "$out/walker.frf" --capture "$out/capture" --frames 3 \
  --lights 256
# The walker leaving frf: a .glb any glTF viewer walks (hull meshes) and a player
# relights (docs/export.md), with the forest's L2 light beside it (turned as the scene
# turns it), drawn by the web player in headless Chromium from the shot's camera at 1 s.
step export $frf export "$out/walker.frf" --out "$out/walker.glb"
step env-sh $frf env-sh assets/envmaps/forest_slope_1k.hdr --yaw 90 --out "$out/forest_sh.json"
step player node player/screenshot.mjs --glb "$out/walker.glb" --pose 0 --camera 0.4,1.5,3.5 \
  --look-at 0.1,0.9,0 --fov 40 --size 256x192 --sh "$out/forest_sh.json" --out "$out/player.png" \
  --time-frames 3

{
  echo "frf demo: $scene, $(nproc) cores, $(date -u +%Y-%m-%dT%H:%MZ)"
  echo
  echo "time per step (wall seconds):"
  awk -F'\t' '{ printf "  %-8s %7.1f\n", $1, $2; s += $2 } END { printf "  %-8s %7.1f\n", "total", s }' "$times"
  echo
  echo "stage (virtual light stage, films what the scene needs):"
  grep -E "^for the scene|^work units|^capture size" "$out/stage.log" | sed 's/^/  /'
  echo
  echo "ingest, against the stage's truth:"
  sed -n '/against the virtual stage/,/^  field:/p' "$out/ingest.log" | sed '1d'
  echo
  echo "render:"
  grep -E "frames in|^shadow|plan:" "$out/render.log" | sed 's/^/  /'
  echo
  echo "frames of the shot against their true composites:"
  sed 's/^/  /' "$out/eval.log"
  echo
  echo "export (the walker as glTF, docs/export.md):"
  sed 's/^/  /' "$out/export.log"
  echo
  echo "the web player (player/, headless Chromium on software GL):"
  sed 's/^/  /' "$out/player.log"
} > "$out/report.txt"
cat "$out/report.txt"
echo "demo: the shot in $out/shot/ (frames, preview.png animated, contact.png), the walker as $out/walker.glb and drawn by the web player in $out/player.png, report $out/report.txt"
