#!/usr/bin/env bash
# Edge-band error of the registered basis images before and after edge decontamination,
# for each `--edge` method, on virtual-stage captures (default flow preset).
# Usage: benches/ingest_edges.sh CAPTURE [CAPTURE...]   (writes one markdown table)
# Example: ./target/release/frf stage --preset tiny --out /tmp/tiny
#          ./target/release/frf stage --preset small --out /tmp/small
#          benches/ingest_edges.sh /tmp/tiny /tmp/small
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for cap in "$@"; do
  for edge in none solve extend; do
    ./target/release/frf ingest "$cap" --out "$work/f.frf" --edge "$edge" \
      --report "$work/$(basename "$cap")_$edge.json" > /dev/null
    rm -f "$work/f.frf"
  done
done
python3 - "$work" "$@" <<'PY'
import json, sys, os
work, caps = sys.argv[1], sys.argv[2:]
print("| capture | `--edge` | edge band error over black | over bright | registered PSNR (dB) | alpha IoU | alpha MAE | flow EPE horizontal (px) |")
print("|---|---|---|---|---|---|---|---|")
for cap in caps:
    for edge in ["none", "solve", "extend"]:
        r = json.load(open(os.path.join(work, f"{os.path.basename(cap)}_{edge}.json")))
        print(f"| {os.path.basename(cap)} ({r['width']}x{r['height']}) | {edge} | "
              f"{r['edge_band_error_dark']:.4f} | {r['edge_band_error_bright']:.4f} | "
              f"{r['registration_psnr']:.2f} | {r['alpha_iou']:.4f} | {r['alpha_mae']:.4f} | "
              f"{r['flow_epe_horizontal']:.3f} |")
PY
