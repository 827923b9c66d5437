#!/usr/bin/env bash
# Issue 25's measurement: a crowd scene (scenes/crowd.toml: 40 walkers over 12 m x 11 m,
# a camera 12 m back, 640x360) rendered with its first N walkers (N = 1, 10, 40, and 100
# with 60 more drawn over the same ground), under a constant light (3 frames)
# and under one turning every frame (12 frames), on a field of every view (e.g. the
# small preset's: `frf stage --preset small --poses 0,1,2 --perturbation 0 --out cap`,
# `frf ingest cap --out f.frf`). Prints, per N and light, the wall time, the mean and median
# seconds a frame, the poses made
# resident and their seconds, the bytes read and the peak resident bytes, from each
# render's render.json. Run it with two binaries to compare them in one run.
# Usage: benches/crowd/run.sh FIELD WORKDIR [FRF...]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
field=$1
work=$2
shift 2
bins=("${@:-target/release/frf}")
mkdir -p "$work"
scene="$here/../../scenes/crowd.toml"
for n in 1 10 40 100; do
  for light in constant turning; do
    python3 - "$scene" "$n" "$light" > "$work/crowd_${n}_$light.toml" <<'PY'
import sys, re
text, n, light = open(sys.argv[1]).read(), int(sys.argv[2]), sys.argv[3]
head, *walkers = text.split("[[instance]]")
# Each walker at its nearest pose: the crowd's own costs, not the morph in time's.
head = head.replace("fps = 10.0\n", "fps = 10.0\ninterpolate = \"nearest\"\n")
if light == "constant":
    head = re.sub(r"\[\[lighting\.key\]\][^\[]*", "", head)
else:
    # Twelve frames (as issue 25 measured), the light turning through all of them.
    head = head.replace("end = 0.3\n", "end = 1.2\n", 1)
    head = head.replace("time = 0.3\nyaw_deg = 90.0\n", "time = 1.2\nyaw_deg = 360.0\n", 1)
    assert "end = 1.2" in head and "yaw_deg = 360.0" in head, "the scene's keys moved"
# Past the scene's 40, more walkers over the same ground (a fixed pseudo-random draw).
seed = 25
while len(walkers) < n:
    seed = (seed * 1103515245 + 12345) % 2**31
    x, z = -6.0 + 12.0 * (seed % 1000) / 1000, -9.0 + 11.0 * (seed // 1000 % 1000) / 1000
    walkers.append(f"\nposition = [{x:.2f}, 0.0, {z:.2f}]\nheading_deg = {seed % 360}.0\n"
                   f"time_offset = {(seed // 7 % 100) / 100:.2f}\n\n")
print(head + "".join("[[instance]]" + w for w in walkers[:n]))
PY
  done
done
printf "%-24s %-8s %6s %9s %9s %9s %9s %10s %10s %10s\n" binary walkers light wall_s frame_s median_s resident resident_s read_MB peak_MB
for n in 1 10 40 100; do
  for light in constant turning; do
    for bin in "${bins[@]}"; do
      out="$work/out_$(echo "$bin" | tr / _)_${n}_$light"
      rm -rf "$out"
      "$bin" render "$work/crowd_${n}_$light.toml" --field "$field" --out "$out" > /dev/null 2>&1
      python3 - "$out/render.json" "$bin" "$n" "$light" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); c = r["residency"]
print(f"{sys.argv[2][-24:]:<24} {sys.argv[3]:<8} {sys.argv[4]:>6} {r['seconds_wall']:9.1f} "
      f"{r['seconds_per_frame_mean']:9.2f} {r['seconds_per_frame_median']:9.2f} "
      f"{c['poses_made_resident']:9d} {c['residency_seconds']:10.1f} "
      f"{r['bytes_read_measured'] / 1e6:10.1f} {c['peak_resident_bytes'] / 1e6:10.1f}")
PY
    done
  done
done
