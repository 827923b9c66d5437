#!/bin/bash
# Issue 47's figures on a machine with an NVIDIA GPU, no Rust and no network
# (docs/results/realtime.md): the interpolation bench at 320x448 and 1920x1080 (the frame
# pass against its floor pass, every storage format), and `frf bench frame` on a crowd at
# 1920x1080 (1, 40, 100 and 400 walkers, a constant and a turning light, per-pass GPU
# timestamps), this build against a previous one in the same run; then this build's
# frames not read back (as a viewer shows them) and the 40-walker scene at 640x360. Run from the
# repository root with two ignored folders prepared on a machine that has them:
#   .dev/frf        this build (cargo build --release, then strip)
#   .dev/frf-base   optional: the build it is compared with
#   .dev/gpu_vs_cpu optional: the GPU-against-CPU test binary (cargo test --release --test
#                   gpu_vs_cpu --no-run, then strip), run with 4 test threads (issue 58:
#                   it waited forever on a real GPU with several threads)
#   .gl/*.deb       the Vulkan loader and GL dispatch libraries (apt-get download
#                   libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
# The field is made there: the small stage preset, poses 0 and 1, no perturbation,
# ingested with the flow between poses. Results go to $OUT (default ./nvidia-out).
set -u
OUT=${OUT:-nvidia-out}
mkdir -p "$OUT"
if ! ldconfig -p | grep -q libvulkan.so.1; then
  for f in .gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | tee "$OUT/gpu.csv"
W=$(mktemp -d)
start=$(date +%s)
.dev/frf stage --preset small --poses 0,1 --perturbation 0 --out "$W/capture" > "$OUT/stage.log" 2>&1
.dev/frf ingest "$W/capture" --out "$W/small.frf" --pose-flow > "$OUT/ingest.log" 2>&1
echo "field made in $(( $(date +%s) - start )) s"
if [ -x .dev/gpu_vs_cpu ]; then
  # The tests find the tiny stage's field themselves; 4 threads, bounded.
  start=$(date +%s)
  timeout 240 .dev/gpu_vs_cpu --test-threads 4 > "$OUT/gpu_vs_cpu.log" 2>&1
  echo "gpu_vs_cpu, 4 threads: exit $? in $(( $(date +%s) - start )) s"
  grep -E "^test result|FAILED|panicked" "$OUT/gpu_vs_cpu.log"
fi
# The crowd of scenes/crowd.toml with its lighting held (the bench turns it itself).
awk '/^\[\[lighting.key\]\]/{skip=1} /^\[camera\]/{skip=0} !skip' scenes/crowd.toml > "$W/crowd.toml"
for build in base new; do
  F=.dev/frf
  formats=all
  if [ $build = base ]; then
    F=.dev/frf-base
    formats=default
    [ -x $F ] || continue
  fi
  $F bench interp --field "$W/small.frf" --size 320x448 --size 1920x1080 --formats $formats \
    --stages compute --warmup 3 --repeats 10 --cpu-repeats 1 --json \
    > "$OUT/interp_$build.json" 2> "$OUT/interp_$build.log"
  $F bench frame "$W/crowd.toml" --field "$W/small.frf" --size 1920x1080 \
    --walkers 1,40,100,400 --light both --frames 6 --json \
    > "$OUT/frame_$build.json" 2> "$OUT/frame_$build.log"
  # As a viewer shows frames (issue 58's fps targets): nothing read back; this build
  # only (older builds lack the flag).
  if [ $build = new ]; then
    $F bench frame "$W/crowd.toml" --field "$W/small.frf" --size 1920x1080 \
      --walkers 1,100,400 --light both --frames 6 --no-readback --json \
      > "$OUT/frame_unread.json" 2> "$OUT/frame_unread.log"
    # The 40-walker scene at 640x360 (turning over constant, first frame), its light
    # turning as the did (180° over 3 s at 30 fps: 2° a frame).
    $F bench frame "$W/crowd.toml" --field "$W/small.frf" --size 640x360 \
      --walkers 40 --light both --turn-deg 2 --frames 6 --spacing shot --json \
      > "$OUT/frame_640.json" 2> "$OUT/frame_640.log"
  fi
done
for build in base new; do
  [ -e "$OUT/interp_$build.log" ] || continue
  echo "== $build"
  grep -E "^(floor|fourway) .*codes +codes8" "$OUT/interp_$build.log"
  grep -E "^fourway " "$OUT/interp_$build.log" | grep -v "codes +codes8" | sort -k6 -n | head -3
  grep -E "^CPU reference .*fourway " "$OUT/interp_$build.log"
  sed -n '/^walkers/,$p' "$OUT/frame_$build.log"
done
for run in unread 640; do
  [ -e "$OUT/frame_$run.log" ] || continue
  echo "== frame bench, $run"
  sed -n '/^walkers/,$p' "$OUT/frame_$run.log"
done
