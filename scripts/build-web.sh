#!/bin/sh
# Builds the lab for the browser into web/dist/: index.html, lab.js, and the .wasm
# with the JS that wasm-bindgen generates for it (docs/web.md). Installs what it
# needs when it is missing: the wasm32 target, and wasm-bindgen-cli at the version
# of the wasm-bindgen crate in Cargo.lock (the generated JS must match it).
# web/dist/ is replaced whole at the end, never left half-written.
set -eu
cd "$(dirname "$0")/.."

version=$(sed -n '/^name = "wasm-bindgen"$/{n;s/^version = "\(.*\)"$/\1/p;}' Cargo.lock)
[ -n "$version" ] || { echo "build-web: no wasm-bindgen in Cargo.lock" >&2; exit 1; }

if ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
  rustup target add wasm32-unknown-unknown
fi
if ! wasm-bindgen --version 2>/dev/null | grep -q " $version\$"; then
  echo "build-web: installing wasm-bindgen-cli $version (once; a few minutes)" >&2
  # --locked first, for the versions its authors tested; a registry mirror that lacks
  # one of them (seen here: webpki-roots 1.0.11) gets the newest compatible ones.
  cargo install wasm-bindgen-cli --version "$version" --locked ||
    cargo install wasm-bindgen-cli --version "$version"
fi

cargo build --release --target wasm32-unknown-unknown -p gnomon-web
# Where cargo put it: `target/`, unless CARGO_TARGET_DIR or a cargo config says otherwise.
target_dir=$(cargo metadata --format-version 1 --no-deps |
  python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')

staging=web/dist.partial
rm -rf "$staging"
mkdir -p "$staging"
wasm-bindgen --target web --no-typescript --out-dir "$staging" --out-name gnomon \
  "$target_dir/wasm32-unknown-unknown/release/gnomon_web.wasm"
cp web/page/index.html web/page/lab.js web/page/lab.css web/page/viewer.html web/page/viewer.js "$staging"/
rm -rf web/dist
mv "$staging" web/dist
echo "build-web: wrote web/dist/ ($(du -sh web/dist | cut -f1)); serve it with: sh scripts/serve-web.sh" >&2
