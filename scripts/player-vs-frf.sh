#!/usr/bin/env bash
# The web player against `frf render`: pose 0 of FIELD exported, lit by the built-in sky's
# L2 light (or the light file LIGHT, with its suns) and optionally a sun, drawn by both
# from cameras of the grid (captured views at integer U,V, quad centres at halves) and
# compared (subject PSNR, player/compare.mjs).
#   scripts/player-vs-frf.sh FIELD OUT_DIR [U,V[,SUN_AZ,SUN_EL,SUN_E]] ...
set -euo pipefail
field=$1; out=$2; shift 2
frf=${FRF:-target/release/frf}
mkdir -p "$out"
# EXPORT_ARGS: more options of the export (e.g. --mesh-voxel 0.01).
# shellcheck disable=SC2086
"$frf" export "$field" --poses 0 ${EXPORT_ARGS:-} --out "$out/walker.glb" >/dev/null
# LIGHT: a light file of `frf env-sh` (its suns too, `--suns`) instead of the sky's L2.
if [ -n "${LIGHT:-}" ]; then cp "$LIGHT" "$out/sky.json"; else "$frf" env-sh sky --out "$out/sky.json" >/dev/null; fi
for case in "$@"; do
  IFS=, read -r u v az el e <<< "$case"
  name="${u}_${v}${az:+_sun_${az}_${el}_${e}}"
  read -r -a flags <<< "$(node player/grid-camera.mjs "$out/walker.glb" "$u,$v")"
  sun=(); frfsun=()
  if [ -n "${az:-}" ]; then sun=(--sun "$az,$el,0.53,$e"); frfsun=(--sun "$az,$el,0.53,$e"); fi
  node player/screenshot.mjs --glb "$out/walker.glb" --pose 0 "${flags[@]}" --sh "$out/sky.json" \
    "${sun[@]}" --out "$out/$name-player.png" >/dev/null
  cam=${flags[0]#--camera=}; look=${flags[1]#--look-at=}
  printf '[[key]]\ntime = 0.0\nposition = [%s]\nlook_at = [%s]\nfov_deg = %s\n' "$cam" "$look" "${flags[3]}" > "$out/$name.toml"
  "$frf" render "$field" --env "$out/sky.json" "${frfsun[@]}" --camera "$out/$name.toml" --frames 1 \
    --pose 0 --shadow none --detail 0 --size "${flags[5]}" --out "$out/$name-frf" --overwrite >/dev/null 2>&1
  echo "$case: $(node player/compare.mjs "$out/$name-frf/frame_0000.png" "$out/$name-player.png")"
done
