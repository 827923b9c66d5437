#!/usr/bin/env bash
# Installs what a fresh Debian machine with Rust lacks for this project, and nothing
# that is already there:
# - Mesa's software Vulkan driver (lavapipe) and the Vulkan loader, the GPU of machines
#   without one (the wgpu renderer runs on it);
# - Xvfb (a display without a screen), xauth and xdotool, for the viewer's tests (`frf view`
#   under `xvfb-run`), and the X libraries winit opens at run time (cursor, input,
#   keyboard) that they do not bring;
# - Node.js and npm, and the web player's npm packages (player/package-lock.json: three.js,
#   fast-png, puppeteer-core and the Khronos glTF validator), for the export's and the
#   player's tests;
# - Debian's Chromium, the real browser the player's tests drive headless (software GL);
# - a C++ compiler, for the Basis Universal encoder the export's KTX2 atlases are made by
#   (built from source by the basis-universal crate);
# - the rustfmt and clippy components, for the checks in .ci/run.
set -euo pipefail

packages=(mesa-vulkan-drivers libvulkan1 xvfb xauth xdotool libxcursor1 libxi6 libxkbcommon-x11-0)
command -v node >/dev/null 2>&1 || packages+=(nodejs)
command -v npm >/dev/null 2>&1 || packages+=(npm)
command -v chromium >/dev/null 2>&1 || packages+=(chromium)
command -v c++ >/dev/null 2>&1 || packages+=(g++)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if command -v rustup >/dev/null 2>&1; then
  for c in rustfmt clippy; do
    rustup component list --installed 2>/dev/null | grep -q "^$c" || rustup component add "$c" >/dev/null 2>&1 || true
  done
fi

# The player's packages, as its lock file pins them (again when the lock file changes).
player="$(dirname "$0")/../player"
if [ ! -f "$player/node_modules/.package-lock.json" ] ||
   [ "$player/package-lock.json" -nt "$player/node_modules/.package-lock.json" ]; then
  echo "setup: installing the player's npm packages"
  (cd "$player" && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
fi
