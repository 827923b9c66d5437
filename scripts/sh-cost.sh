#!/usr/bin/env bash
# What L2 costs: frf under an environment's nine SH coefficients (`frf env-sh`) against
# frf under the environment itself, same field, cameras and floor, per environment.
# Subject PSNR over the frames' EXR (alpha > 0.5 in both; peak: the environment's frame).
#   scripts/sh-cost.sh FIELD OUT_DIR [ENV ...]   (default: sky and the shared envmaps)
# Needs numpy and OpenEXR in Python: a venv under OUT_DIR/venv is made when missing.
set -euo pipefail
field=$1; out=$2; shift 2
frf=${FRF:-target/release/frf}
envs=("$@")
if [ ${#envs[@]} -eq 0 ]; then
  envs=(sky)
  for e in ../shared/data/envmaps/*.hdr; do [ -f "$e" ] && envs+=("$e"); done
fi
mkdir -p "$out"
py="$out/venv/bin/python"
if [ ! -x "$py" ]; then
  python3 -m venv "$out/venv" && "$out/venv/bin/pip" -q install numpy OpenEXR
fi
for env in "${envs[@]}"; do
  name=$(basename "$env" .hdr)
  "$frf" env-sh "$env" --out "$out/$name.json" | grep -E "energy|rings" | tr -s ' ' | sed "s/^/$name:/"
  for light in "$env" "$out/$name.json"; do
    tag=$([ "$light" = "$env" ] && echo env || echo sh)
    "$frf" render "$field" --env "$light" --orbit 3.2,1.3 --frames 4 --size 160x224 \
      --out "$out/$name-$tag" --overwrite >/dev/null 2>&1
  done
  "$py" - "$out/$name-env" "$out/$name-sh" "$name" <<'PY'
import sys, glob, os, numpy as np, OpenEXR
a_dir, b_dir, name = sys.argv[1:4]
def load(p):
    with OpenEXR.File(p) as f:
        ch = f.channels()
        if "RGBA" in ch:
            return np.asarray(ch["RGBA"].pixels, dtype=np.float64)
        return np.stack([np.asarray(ch[c].pixels, dtype=np.float64) for c in "RGBA"], -1)
se, n, peak = 0.0, 0, 0.0
for p in sorted(glob.glob(os.path.join(a_dir, "frame_*.exr"))):
    a, b = load(p), load(os.path.join(b_dir, os.path.basename(p)))
    m = (a[..., 3] > 0.5) & (b[..., 3] > 0.5)
    se += ((a[m][:, :3] - b[m][:, :3]) ** 2).sum(); n += 3 * m.sum(); peak = max(peak, a[m][:, :3].max())
print(f"{name}: subject PSNR, frf under L2 against frf under the map: {10*np.log10(peak**2/(se/n)):.2f} dB")
PY
done
