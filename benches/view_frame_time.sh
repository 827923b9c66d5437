#!/usr/bin/env bash
# Frame time of `frf view` (GPU time per frame from timestamp queries, frames per second
# shown, median over the frames after the first) at several window sizes, beside `frf
# render` of the same camera on the GPU (with its readback and PNG/EXR writing) and on
# the CPU reference. Runs the viewer under Xvfb; prints a Markdown table.
#
#   benches/view_frame_time.sh FIELD [FRAMES] [SIZES...]
#   benches/view_frame_time.sh demo-out/walker.frf 12 320x240 640x480 1280x720
set -euo pipefail
field=${1:?a field file}
frames=${2:-12}
shift 2 || true
sizes=("$@")
[ ${#sizes[@]} -eq 0 ] && sizes=(320x240 640x480 1280x720)
frf=${FRF:-target/release/frf}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$work}"
cat > "$work/path.toml" <<'TOML'
[[key]]
time = 0.0
position = [2.2, 1.3, 2.6]
look_at = [0.0, 0.9, 0.0]
fov_deg = 32.0
TOML
printf 'camera 2.2 1.3 2.6  0 0.9 0  32\nwait %s\nquit\n' "$frames" > "$work/script.txt"
median() { sort -g | awk '{v[NR]=$1} END {print v[int((NR+1)/2)]}'; }
echo "| size | viewer GPU time per frame | viewer frames per second | frf render GPU, s/frame | frf render CPU reference, s/frame |"
echo "|---|---|---|---|---|"
for s in "${sizes[@]}"; do
  w=${s%x*}; h=${s#*x}
  xvfb-run -a -s "-screen 0 $((w + 64))x$((h + 64))x24" \
    "$frf" view "$field" --size "$s" --no-vsync --script "$work/script.txt" --json \
    > "$work/view.json" 2> "$work/view.log"
  gpu=$(python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print('%.1f ms' % r['gpu_ms_median'] if r['gpu_ms_median'] else 'n/a')" "$work/view.json")
  fps=$(python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print('%.2f' % r['fps_median'] if r['fps_median'] else 'n/a')" "$work/view.json")
  per_frame() {
    rm -rf "$work/out"
    "$frf" render "$field" --camera "$work/path.toml" --env sky --backdrop env --size "$s" \
      --frames 3 --out "$work/out" "$@" 2>&1 | sed -n 's/.*: \([0-9.]*\) s\/frame median.*/\1/p'
  }
  echo "| $s | $gpu | $fps | $(per_frame) | $(per_frame --cpu) |"
done
