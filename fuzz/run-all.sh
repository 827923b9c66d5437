#!/usr/bin/env bash
# Runs every fuzz target for SECONDS each (default 600), one after another, each starting
# from its seeds, and prints the runs and coverage each reached. Logs: fuzz/logs/<target>.log.
# Needs cargo-fuzz (`cargo install cargo-fuzz --locked`); RUSTC_BOOTSTRAP=1 lets a stable
# toolchain build with the sanitizer-coverage flags cargo-fuzz passes.
set -euo pipefail
cd "$(dirname "$0")"
seconds=${1:-600}
targets=${TARGETS:-"container huffman images flo manifest scene env olat"}
mkdir -p logs
RUSTC_BOOTSTRAP=1 cargo fuzz build -s none
for t in $targets; do
    mkdir -p "corpus/$t" "artifacts/$t"
    if [ -d "seeds/$t" ]; then cp -n seeds/"$t"/* "corpus/$t/" 2>/dev/null || true; fi
    RUSTC_BOOTSTRAP=1 cargo fuzz run -s none "$t" "corpus/$t" -- \
        -max_total_time="$seconds" -rss_limit_mb=2048 -print_final_stats=1 \
        >"logs/$t.log" 2>&1 || echo "$t: libFuzzer stopped with a finding, see logs/$t.log"
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "logs/$t.log" | grep -o '[0-9]*$' || echo '?')
    cov=$(grep -o 'cov: [0-9]*' "logs/$t.log" | tail -1 | grep -o '[0-9]*' || echo '?')
    found=$(find "artifacts/$t" -type f | wc -l)
    echo "$t: ${seconds} s, ${runs} runs, ${cov} coverage edges, ${found} findings"
done
