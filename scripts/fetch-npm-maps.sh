#!/usr/bin/env bash
# Real HDR environment maps for reporting hard light on maps it was not tuned on: the 18
# latitude-longitude EXRs of the npm package @pmndrs/assets (Poly Haven's, CC0, 1k,
# shipped base64-encoded in JavaScript modules), decoded into DIR/NAME.exr, and the
# split into maps to develop on and maps to report on, fixed before any was looked at:
# `bridge` (the overcast map an earlier report found wrong) and, of the other 17 in
# alphabetical order, the 1st, 3rd, 5th, ... to develop on; the rest to report on.
#   scripts/fetch-npm-maps.sh DIR   (writes DIR/dev.txt and DIR/report.txt)
set -euo pipefail
dir=${1:?usage: scripts/fetch-npm-maps.sh DIR}
mkdir -p "$dir"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
(cd "$work" && npm pack @pmndrs/assets@1.7.0 --silent >/dev/null && tar xzf pmndrs-assets-1.7.0.tgz)
python3 - "$work/package/hdri" "$dir" <<'PY'
import base64, pathlib, sys
src, out = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
names = sorted(p.name[: -len(".exr.js")] for p in src.glob("*.exr.js"))
for n in names:
    text = (src / f"{n}.exr.js").read_text()
    data = text[text.index("base64,") + 7 : text.rindex("'")]
    (out / f"{n}.exr").write_bytes(base64.b64decode(data))
rest = [n for n in names if n != "bridge"]
dev = ["bridge"] + rest[0::2]
report = rest[1::2]
(out / "dev.txt").write_text("\n".join(dev) + "\n")
(out / "report.txt").write_text("\n".join(report) + "\n")
print(f"{len(names)} maps in {out}: develop on {' '.join(dev)}; report on {' '.join(report)}")
PY
