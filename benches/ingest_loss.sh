#!/usr/bin/env bash
# What ingest loses at the captured views, map by map: an oracle field (`frf stage field`)
# and the ingested field of the same capture, scored by `frf eval` (subject PSNR of the
# four-way morph at 8 captured views of pose 0 against the stage's truth), and the mean
# loss. Lighter than benches/ingest_budget.sh (no field per component): 12 s a map and
# field on lavapipe for the small preset.
# Usage: benches/ingest_loss.sh CAPTURE ORACLE INGESTED OUTDIR [FRF] [MAP...]
#   MAP: `sky` or an HDR map; default the built-in sky and $FRF_DATA_DIR/envmaps/*.hdr
#   (default ../shared/data/envmaps). EVAL_FLAGS adds flags to frf eval (e.g. `--cpu`).
set -euo pipefail
cap=$1
oracle=$2
ingested=$3
out=$4
frf=${5:-target/release/frf}
shift $(( $# < 5 ? $# : 5 ))
data=${FRF_DATA_DIR:-$(cd "$(dirname "$0")/../.." && pwd)/shared/data}
maps=("$@")
if [ ${#maps[@]} -eq 0 ]; then
  maps=(sky)
  for e in "$data"/envmaps/*.hdr; do maps+=("$e"); done
fi
mkdir -p "$out"
for m in "${maps[@]}"; do
  name=$(basename "$m"); name=${name%.*}
  for kind in oracle ingested; do
    field=$oracle; [ "$kind" = ingested ] && field=$ingested
    # shellcheck disable=SC2086
    "$frf" eval "$field" --capture "$cap" --pose 0 --env "$m" --cameras 8 ${EVAL_FLAGS:-} \
      --json > "$out/${name}_$kind.json" 2> "$out/${name}_$kind.log"
  done
done
python3 - "$out" "${maps[@]}" <<'PY'
import json, os, sys
out, maps = sys.argv[1], sys.argv[2:]
score = lambda n, k: json.load(open(f"{out}/{n}_{k}.json"))["at_captured_views"]["psnr_subject"]
print("| map | oracle | ingested | lost |")
print("|---|---|---|---|")
lost = []
for m in maps:
    n = os.path.splitext(os.path.basename(m))[0]
    o, i = score(n, "oracle"), score(n, "ingested")
    lost.append(o - i)
    print(f"| {n} | {o:.2f} | {i:.2f} | {o - i:.2f} |")
print(f"| mean of {len(lost)} | | | **{sum(lost) / len(lost):.2f}** (worst {max(lost):.2f}) |")
PY
