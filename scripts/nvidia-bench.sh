#!/bin/bash
# The interpolation bench and a 1080p render sequence on a machine with an NVIDIA GPU,
# no Rust and no network (see docs/results/render.md, "GPU interpolation bench"). Run
# from the repository root, with an ignored folder `device/` prepared on a machine that
# has them:
#   device/frf         the release binary, stripped (cargo build --release; strip)
#   device/gl/*.deb    the Vulkan loader and GL dispatch libraries: apt-get download
#                      libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2
#   device/field.frf   a field to render (e.g. frf stage field --capture small ...)
#   device/env.hdr     an HDR environment
#   device/x/*.deb     optional, for the viewer's frame time: apt-get download xvfb xauth
#                      and the X libraries it lacks there (`frf view` needs a display)
# Results go to $OUT (default ./nvidia-out): gpu.csv, bench.json, bench.log, and per
# size render_WxH.json with the render log; with Xvfb, view_frame_time.md (the viewer's
# GPU time per frame and frames per second at 1080p and 4K, benches/view_frame_time.sh).
set -u
OUT=${OUT:-nvidia-out}
mkdir -p "$OUT"
if ! ldconfig -p | grep -q libvulkan.so.1; then
  for f in device/gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm,clocks.max.mem \
  --format=csv > "$OUT/gpu.csv" 2>&1
cat "$OUT/gpu.csv"
F=device/frf
( time $F bench interp --json ${BENCH_ARGS:-} > "$OUT/bench.json" ) 2> "$OUT/bench.log"
tail -6 "$OUT/bench.log"
for s in 320x448 1920x1080; do
  ( time $F render device/field.frf --env device/env.hdr --orbit 3,1.2 \
      --frames "${FRAMES:-48}" --size $s --out /tmp/render_$s --overwrite ) \
    2> "$OUT/render_$s.log"
  cp /tmp/render_$s/render.json "$OUT/render_$s.json" 2>/dev/null
  tail -4 "$OUT/render_$s.log"
done
if ! command -v xvfb-run >/dev/null 2>&1; then
  for f in device/x/*.deb; do [ -e "$f" ] && dpkg -x "$f" /; done
  ldconfig
fi
if command -v xvfb-run >/dev/null 2>&1; then
  FRF=$F benches/view_frame_time.sh device/field.frf 24 1920x1080 3840x2160 \
    > "$OUT/view_frame_time.md" 2> "$OUT/view_frame_time.log"
  cat "$OUT/view_frame_time.md"
else
  echo "no xvfb-run: the viewer's frame time is not measured (device/x/*.deb)"
fi
