#!/usr/bin/env bash
# The demo, end to end on built-in data: the virtual light stage films the walker
# (small preset, 160x224, 36x3 views, 2 poses) with its ground truth, ingest turns the
# capture into a flowed reflectance field (reporting each step's error against the
# truth), then the stage renders the
# true image of a novel camera under an HDR environment (a USC ICT light probe from
# ../shared/data when present, else the built-in sky). Output in demo-out/ (resumable:
# a rerun continues an interrupted one).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cargo build --release --quiet
out="${1:-demo-out}"
frf=./target/release/frf
$frf stage --preset small --out "$out/capture"
$frf ingest "$out/capture" --out "$out/walker.frf" --report "$out/ingest_report.json"
$frf info "$out/walker.frf"
env=../shared/data/envmaps/grace.hdr
[ -f "$env" ] || env=sky
$frf stage truth --capture "$out/capture" --eye 2.5,1.6,3.0 --look-at 0,0.9,0 \
  --env "$env" --out "$out/truth_novel_view.png"
echo "demo: contact sheets in $out/capture/preview/, field $out/walker.frf with report $out/ingest_report.json, novel-view ground truth in $out/truth_novel_view.png"
