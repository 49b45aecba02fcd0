#!/bin/sh
# The main job: install what is missing, build, encode the gallery, serve the
# progressive viewer and print its URL. PORT (default 8080) picks the port.
set -eu
cd "$(dirname "$0")/.."
sh scripts/build.sh
if [ ! -d node_modules/three ]; then npm install --no-audit --no-fund; fi
sh scripts/gallery.sh
exec node web/server.mjs --root out --port "${PORT:-8080}"
