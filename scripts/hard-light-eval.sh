#!/usr/bin/env bash
# Hard light per map: the suns frf finds in each map and the subject PSNR, at 8 captured
# views of pose 0, of the sun relit by the basis alone and by the fitted normals
# (`frf eval --sun-fit`), against the truth of CAPTURE (a zero-perturbation capture and
# its oracle field, `frf stage field`, isolate the relighting).
#   scripts/hard-light-eval.sh FIELD CAPTURE MAP|sky ...   (FRF: the binary, default target/release/frf)
set -uo pipefail
frf=${FRF:-target/release/frf}; field=$1; cap=$2; shift 2
for m in "$@"; do
  json=$(mktemp); err=$(mktemp)
  if ! "$frf" eval "$field" --capture "$cap" --pose 0 --env "$m" --cameras 8 --sun-fit --json > "$json" 2> "$err"; then
    echo "$(basename "$m"): $(tail -1 "$err")"; rm -f "$json" "$err"; continue
  fi
  python3 -c "
import json,sys
d=json.load(open(sys.argv[2])); b=d['basis']['psnr_subject']; f=d['fit']['psnr_subject']
print(f\"{sys.argv[1]:<18} suns {d['suns']}  basis {b:6.2f}  normals {f:6.2f}  gain {f-b:+6.2f}\")" "$(basename "$m" .exr)" "$json"
  rm -f "$json" "$err"
done
