#!/usr/bin/env bash
# Runs the whole test suite (every crate's unit and integration tests), after installing
# what a fresh machine lacks. Tests on the real data under ../shared/data run when it is
# present (or FRF_DATA_DIR points to it) and say that they skip otherwise.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
chmod 700 "$XDG_RUNTIME_DIR"
cargo test --workspace --all-targets "$@"
