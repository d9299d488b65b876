#!/bin/sh
# Issue 49's small hostile files (crates/fuzz/seeds/gltf), each rendered by the
# release binary: what it prints and the process's peak memory (maximum resident
# set, from /usr/bin/time). The 8 GB buffer's file is made beside its model as a
# sparse file (it takes no disk).
#
#   sh scripts/hostile-memory.sh [GNOMON]
set -eu
gnomon=${1:-target/release/gnomon}
seeds="$(dirname "$0")/../crates/fuzz/seeds/gltf"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/model"
cp "$seeds"/*.gltf "$work/model/"
truncate -s 8G "$work/model/huge.bin"
echo "| file | peak memory | exit | what it prints |"
echo "|---|---|---|---|"
for file in "$work"/model/*.gltf; do
  name=$(basename "$file")
  set +e
  /usr/bin/time -f "%M" -o "$work/rss" "$gnomon" render "$file" --width 64 --height 36 --out "$work/out.png" \
    > /dev/null 2> "$work/said"
  status=$?
  set -e
  rss_kb=$(tail -n 1 "$work/rss")
  said=$(grep -m 1 "error" "$work/said" | sed "s|$work/model/||g" | cut -c1-220)
  echo "| \`$name\` | $((rss_kb / 1024)) MB | $status | $said |"
done
