#!/bin/sh
# Serves web/dist/ (built by scripts/build-web.sh) on 127.0.0.1, port $1 or 8080:
# a page cannot load its .wasm from file://. Open the address it prints in a browser
# with WebGPU (docs/web.md).
set -eu
cd "$(dirname "$0")/../web/dist" 2>/dev/null || {
  echo "serve-web: no web/dist/; build it first: sh scripts/build-web.sh" >&2
  exit 1
}
port=${1:-8080}
echo "serve-web: http://127.0.0.1:$port/ (Ctrl-C stops it)" >&2
exec python3 -m http.server --bind 127.0.0.1 "$port"
