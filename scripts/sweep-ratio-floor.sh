#!/usr/bin/env bash
# Chooses the light fit's RATIO_FLOOR (reflectance/src/light_fit.rs) on one part of the
# UW one-light-at-a-time sets and reports it on another: for each value, the constant is
# written, frf rebuilt (release) and `frf eval-olat SET --use 6 --json` run on the dev sets
# (gray, owl, cat: the value with the highest summed mean PSNR is chosen) and the report
# set (buddha). Prints "value set fit_psnr interpolation_psnr" a line; restores the file.
# Usage: scripts/sweep-ratio-floor.sh [VALUES...] (default 0.3 0.05 0.8). Needs the shared
# data (../shared/data/olat/uw_psm, or FRF_DATA_DIR).
set -euo pipefail
cd "$(dirname "$0")/.."
data="${FRF_DATA_DIR:-../shared/data}/olat/uw_psm"
values=("$@")
[ ${#values[@]} -gt 0 ] || values=(0.3 0.05 0.8)
file=reflectance/src/light_fit.rs
trap 'git checkout -- "$file"' EXIT
for v in "${values[@]}"; do
    sed -i "s/^pub const RATIO_FLOOR: f32 = .*;/pub const RATIO_FLOOR: f32 = $v;/" "$file"
    cargo build --release --bin frf >/dev/null 2>&1
    for s in gray owl cat buddha; do
        ./target/release/frf eval-olat "$data/$s" --use 6 --json 2>/dev/null | python3 -c \
            "import json,sys; r=json.load(sys.stdin); print('$v $s', round(r['mean_psnr'], 3), round(r['baselines']['interpolated']['mean_psnr'], 3))"
    done
done
