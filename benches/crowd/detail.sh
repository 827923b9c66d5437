#!/usr/bin/env bash
# Issue 25's level-of-detail measurement: one walker seen from further and further away
# (a camera 1 m up, looking at its middle, 640x360, 55°), drawn at every level of detail
# (`frf render --detail L`), each level's walker scored against full detail: the PSNR of
# its premultiplied layer (frame_0000_subject.exr) over the pixels either covers, peak 1,
# (a) against level 0 drawn at the same size (one sample a pixel: aliased where the walker
# is small), and (b) against level 0 drawn at 4x the size and averaged over each 4x4
# block (full detail filtered as a pixel sees it). Beside them, the walker's height in
# the frame (rows more than half covered) and the level `frf render` picks by default.
# Needs python3 with numpy and OpenEXR (e.g. `pip install numpy OpenEXR` in a venv).
# Usage: benches/crowd/detail.sh FIELD WORKDIR [FRF]
set -euo pipefail
field=$1
work=$2
bin=${3:-target/release/frf}
mkdir -p "$work"
printf "%-8s %-9s %-5s %-28s %s\n" distance height auto "(a) levels 1, 2, 3 (dB)" "(b) levels 0, 1, 2, 3 (dB)"
for d in 3 4.5 6 9 12 18 24; do
  cat > "$work/one_$d.toml" <<TOML
[time]
start = 0.0
end = 0.0
fps = 10.0
interpolate = "nearest"
[output]
size = [640, 360]
[lighting]
env = "sky"
[camera]
[[camera.key]]
time = 0.0
position = [0.0, 1.0, $d]
look_at = [0.0, 1.0, 0.0]
fov_deg = 55.0
[composite]
backdrop = "env"
shadow = "none"
[[instance]]
position = [0.0, 0.0, 0.0]
heading_deg = 30.0
TOML
  sed 's/size = \[640, 360\]/size = [2560, 1440]/' "$work/one_$d.toml" > "$work/four_$d.toml"
  rm -rf "$work/four_$d"
  "$bin" render "$work/four_$d.toml" --field "$field" --out "$work/four_$d" --detail 0 --layers \
    > /dev/null 2>&1
  for level in 0 1 2 3; do
    out="$work/one_${d}_$level"
    rm -rf "$out"
    "$bin" render "$work/one_$d.toml" --field "$field" --out "$out" --detail "$level" --layers \
      > /dev/null 2>&1
  done
  auto=$("$bin" render "$work/one_$d.toml" --field "$field" --plan --json 2>/dev/null |
    python3 -c "import json, sys; print(json.load(sys.stdin)['walker_counts'][0]['levels'][0])")
  python3 - "$work" "$d" "$auto" <<'PY'
import sys, math
import numpy as np, OpenEXR
work, d, auto = sys.argv[1], sys.argv[2], sys.argv[3]
def layer(level):
    f = OpenEXR.File(f"{work}/one_{d}_{level}/frame_0000_subject.exr")
    ch = f.channels()
    if "RGBA" in ch:
        return ch["RGBA"].pixels.astype(np.float64)
    return np.dstack([ch[c].pixels for c in "RGBA"]).astype(np.float64)
def psnr(img, ref):
    mask = (ref[..., 3] > 0) | (img[..., 3] > 0)
    mse = ((img - ref)[mask] ** 2).mean() if mask.any() else 0.0
    return math.inf if mse == 0 else 10 * math.log10(1.0 / mse)
full = layer(0)
f = OpenEXR.File(f"{work}/four_{d}/frame_0000_subject.exr").channels()
four = f["RGBA"].pixels if "RGBA" in f else np.dstack([f[c].pixels for c in "RGBA"])
filtered = four.astype(np.float64).reshape(360, 4, 640, 4, 4).mean(axis=(1, 3))
a = [psnr(layer(level), full) for level in (1, 2, 3)]
b = [psnr(layer(level), filtered) for level in (0, 1, 2, 3)]
px = int(((full[..., 3] > 0.5).any(axis=1)).sum())
print(f"{d:<8} {px:>5} px  {auto:<5} " + " ".join(f"{s:6.2f}" for s in a) + "        "
      + " ".join(f"{s:6.2f}" for s in b))
PY
done
