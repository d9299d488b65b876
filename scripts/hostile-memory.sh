#!/bin/sh
# Issue 49's small hostile files (crates/fuzz/seeds/gltf), each rendered by the
# release binary: what it prints and the process's peak memory (maximum resident
# set, from /usr/bin/time). The 8 GB buffer's file is made beside its model as a
# sparse file (it takes no disk).
#
#   sh scripts/hostile-memory.sh [GNOMON]
set -eu
gnomon=${1:-target/release/gnomon}
gnomon="$(cd "$(dirname "$gnomon")" && pwd)/$(basename "$gnomon")"
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

# The audit's other cases: flags, scene files, inputs that are not regular files, and
# outputs. Each in the work folder; what it prints (its first error or warning) and
# whether it left anything behind.
echo
echo "| case | exit | what it prints | left behind |"
echo "|---|---|---|---|"
cd "$work"
printf 'builtin = "spheres"\n[[view]]\nname = "a"\neye = [1.0, 1.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\n[[view]]\nname = "a"\neye = [2.0, 1.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\n' > two-views.toml
{ printf 'title = "'; head -c 50000000 /dev/zero | tr '\0' 'x'; printf '\n'; } > long-line.toml
printf '[[model]\nfile = \n' > malformed.toml
mkdir -p a-directory.glb; mkfifo a-fifo.glb; ln -s /dev/zero zero.glb
mknod char-device.png c 1 3
run() {
  label=$1; shift
  before=$(ls -A | sort | md5sum)
  set +e
  timeout 120 "$@" > /dev/null 2> said
  status=$?
  set -e
  after=$(ls -A | sort | md5sum)
  left=$([ "$before" = "$after" ] && echo nothing || echo "**files changed**")
  [ -c char-device.png ] || left="**char-device.png replaced**"
  said_line=$(grep -m 1 -E "error|warning" said | sed "s|$work/||g" | cut -c1-240)
  echo "| $label | $status | $said_line | $left |"
}
run '`render --width 16384 --height 16384`' "$gnomon" render --width 16384 --height 16384 --out big.png
mkdir valid
run '`render lamps:64 --light all --shadow-res 8192` (valid: it renders)' "$gnomon" render lamps:64 --light all --shadow-res 8192 --width 64 --height 36 --out valid/lamps.png
run 'two `[[view]]`s named `a`' "$gnomon" render two-views.toml --width 64 --height 36 --out two.png
run 'a scene file with a 50 MB line' "$gnomon" render long-line.toml --out long.png
run 'the model is a directory' "$gnomon" render a-directory.glb --out d.png
run 'the model is a FIFO' "$gnomon" render a-fifo.glb --out f.png
run 'the model is a symlink to /dev/zero' "$gnomon" render zero.glb --out z.png
run '`--out` names a character device' "$gnomon" render --width 64 --height 36 --out char-device.png
run '`calibrate --write /proc/cal.toml`' "$gnomon" calibrate --width 64 --height 36 --out cal --write /proc/cal.toml
run '`calibrate --write` onto malformed TOML' "$gnomon" calibrate --width 64 --height 36 --out cal --write malformed.toml
