#!/usr/bin/env bash
# The demo, end to end on built-in data: the virtual light stage films the walker
# (small preset, 160x224, 36x3 views, 2 poses) with its ground truth, ingest turns the
# capture into a flowed reflectance field (reporting each step's error against the
# truth), the renderer draws an orbit of the walker relit by an HDR environment (a USC
# ICT light probe from ../shared/data when present, else the built-in sky) on the GPU,
# and the four-way morph is scored against its ablations on the stage's truth between
# grid views. Output in demo-out/ (resumable: a rerun continues an interrupted one).
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
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
$frf render "$out/walker.frf" --env "$env" --orbit 3.0,1.2 --frames 36 --out "$out/orbit"
$frf eval "$out/walker.frf" --capture "$out/capture" --env "$env" --cameras 16 \
  --json > "$out/eval.json"
echo "demo: contact sheets in $out/capture/preview/, field $out/walker.frf with report $out/ingest_report.json, orbit frames in $out/orbit/ (contact.png), evaluation in $out/eval.json"
