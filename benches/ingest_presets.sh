#!/usr/bin/env bash
# Error against run time of ingest for each flow preset, on virtual-stage captures.
# Usage: benches/ingest_presets.sh CAPTURE [CAPTURE...]   (writes one markdown table)
#        EDGE=none|solve|extend picks the edge method (default: the ingest's, solve)
# Example: ./target/release/frf stage --preset tiny --out /tmp/tiny
#          ./target/release/frf stage --preset small --out /tmp/small
#          benches/ingest_presets.sh /tmp/tiny /tmp/small
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for cap in "$@"; do
  for preset in fast balanced accurate; do
    ./target/release/frf ingest "$cap" --out "$work/f.frf" --flow-preset "$preset" \
      --edge "${EDGE:-solve}" \
      --report "$work/$(basename "$cap")_$preset.json" > /dev/null
    rm -f "$work/f.frf"
  done
done
python3 - "$work" "$@" <<'PY'
import json, sys, os
work, caps = sys.argv[1], sys.argv[2:]
print("| capture | preset | alpha IoU | alpha MAE | registered / unregistered PSNR (dB) | flow EPE horizontal (px) | flow EPE vertical (px) | ingest seconds per pose (wall, evaluation excluded) |")
print("|---|---|---|---|---|---|---|---|")
for cap in caps:
    for preset in ["fast", "balanced", "accurate"]:
        r = json.load(open(os.path.join(work, f"{os.path.basename(cap)}_{preset}.json")))
        secs = sum(s["seconds"] for s in r["steps"]) / len(r["poses"])
        print(f"| {os.path.basename(cap)} ({r['width']}x{r['height']}) | {preset} | {r['alpha_iou']:.4f} | {r['alpha_mae']:.4f} | "
              f"{r['registration_psnr']:.2f} / {r['unregistered_psnr']:.2f} | {r['flow_epe_horizontal']:.3f} | "
              f"{r['flow_epe_vertical']:.3f} | {secs:.1f} |")
PY
