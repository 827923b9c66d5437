#!/usr/bin/env bash
# The error budget of ingest (frf eval --ingest-budget) of one capture under several
# environments, summarised as the Markdown tables of docs/results/ingest.md: per
# environment the oracle and the ingested field at the captured views and at quad
# centres; per component its mean gain and share of the squared error.
# Usage: benches/ingest_budget.sh CAPTURE FIELD OUTDIR [FRF]
#   FIELD: the capture ingested by `frf ingest` (scored beside the budget's own ingest).
#   The environments: the built-in sky and the HDR maps of $FRF_DATA_DIR/envmaps
#   (default ../shared/data/envmaps). The fields are kept in OUTDIR/fields and reused.
#   SUMMARY_ONLY=1 prints the tables of an OUTDIR already measured; BUDGET_FLAGS adds
#   flags to frf eval (e.g. `--inter-view-flow images`).
set -euo pipefail
cap=$1
field=$2
out=$3
frf=${4:-target/release/frf}
data=${FRF_DATA_DIR:-$(cd "$(dirname "$0")/../.." && pwd)/shared/data}
envs=(sky)
for e in "$data"/envmaps/*.hdr; do envs+=("$e"); done
mkdir -p "$out"
if [ -z "${SUMMARY_ONLY:-}" ]; then
  for e in "${envs[@]}"; do
    name=$(basename "$e" .hdr)
    # shellcheck disable=SC2086
    "$frf" eval "$field" --capture "$cap" --env "$e" --ingest-budget --fields "$out/fields" \
      ${BUDGET_FLAGS:-} --json > "$out/$name.json" 2> "$out/$name.log"
  done
fi
python3 - "$out" <<'PY'
import glob, json, os, sys
out = sys.argv[1]
reports = {os.path.basename(p)[:-5]: json.load(open(p)) for p in sorted(glob.glob(f"{out}/*.json"))}
row = lambda r, c: next(x for x in r["rows"] if x["component"] == c)
print("| environment | captured views: oracle | ingested | lost | quad centres: oracle | ingested | lost |")
print("|---|---|---|---|---|---|---|")
lost = {"captured": [], "quad_centres": []}
for name, r in reports.items():
    o, i = row(r, "oracle"), row(r, "ingested")
    cells = []
    for place in ["captured", "quad_centres"]:
        a, b = o[place]["psnr_subject"], i[place]["psnr_subject"]
        lost[place].append(a - b)
        cells += [f"{a:.2f}", f"{b:.2f}", f"{a - b:.2f}"]
    print(f"| {name} | " + " | ".join(cells) + " |")
n = len(reports)
mean = lambda place, k: sum(row(r, c)[place][k] for r in reports.values()) / n
means = []
for place in ["captured", "quad_centres"]:
    c = "oracle"
    a = sum(row(r, "oracle")[place]["psnr_subject"] for r in reports.values()) / n
    b = sum(row(r, "ingested")[place]["psnr_subject"] for r in reports.values()) / n
    means += [f"**{a:.2f}**", f"**{b:.2f}**", f"**{a - b:.2f}** (worst {max(lost[place]):.2f})"]
print(f"| mean of {n} | " + " | ".join(means) + " |")
print()
print("| taken from the truth | captured views: gain (dB) | share of squared error | quad centres: gain (dB) | share of squared error |")
print("|---|---|---|---|---|")
for c in [x["component"] for x in next(iter(reports.values()))["rows"]][1:]:
    g = lambda place, k: sum(row(r, c)[place][k] for r in reports.values()) / n
    print(f"| {c} | {g('captured', 'gain_db'):+.2f} | {100 * g('captured', 'share_of_squared_error'):.1f} % | {g('quad_centres', 'gain_db'):+.2f} | {100 * g('quad_centres', 'share_of_squared_error'):.1f} % |")
PY
