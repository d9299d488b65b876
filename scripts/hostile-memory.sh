#!/bin/sh
# Issue 49's small hostile files (crates/fuzz/seeds/gltf), each rendered by the
# release binary, and round three's cases (issue 75, scripts/hostile-round3.py): what it prints and the process's peak memory (maximum resident
# set, from /usr/bin/time). The 8 GB buffer's file is made beside its model as a
# sparse file (it takes no disk).
#
#   sh scripts/hostile-memory.sh [GNOMON]
set -eu
root="$(cd "$(dirname "$0")/.." && pwd)"
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

# Round three (issue 75): small files that Gnomon held many times, build steps that
# degenerated, special files, planted links, and checks that came after the work.
# Each under a 120 s timeout; peak memory and wall time from /usr/bin/time.
echo
echo "| round three: case | peak memory | time | exit | what it prints |"
echo "|---|---|---|---|---|"
mkdir -p round3
python3 "$root/scripts/hostile-round3.py" round3
measure() {
  label=$1; shift
  set +e
  /usr/bin/time -f "%M %e" -o rss timeout 120 "$@" > /dev/null 2> said
  status=$?
  set -e
  peak=$(($(tail -n 1 rss | cut -d' ' -f1) / 1024))
  secs=$(tail -n 1 rss | cut -d' ' -f2)
  said_line=$(grep -m 1 -E "error|warning" said | sed "s|$work/||g" | cut -c1-200)
  echo "| $label | $peak MB | $secs s | $status | $said_line |"
}
for file in round3/*.gltf; do
  measure "\`$(basename "$file")\`" "$gnomon" render "$file" --width 64 --height 36 --out r3.png
done
for file in round3/*.toml; do
  measure "\`$(basename "$file")\`" "$gnomon" render "$file" --out r3.png
done
{
  echo 'builtin = "spheres"'
  for i in 0 1 2 3 4 5 6 7; do
    printf '[[light]]\ntype = "point"\nposition = [%s, 3.0, 0.0]\nrange = 20.0\n[light.shadow]\nmap.resolution = 8192\n' "$i"
  done
} > round3/eight-points-of-8192.toml
measure '8 point lights of 8192² (`--light all`)' "$gnomon" render round3/eight-points-of-8192.toml --light all --out r3.png
measure '`--width 4000 --height 4000`' "$gnomon" render --width 4000 --height 4000 --out r3.png
measure '`--width 11585 --height 11585`' "$gnomon" render --width 11585 --height 11585 --out r3.png
measure '`--fov 1e-5`' "$gnomon" render --fov 1e-5 --out r3.png
measure '`--fov 0.01` (the least allowed)' "$gnomon" render --fov 0.01 --width 320 --height 180 --out r3.png
measure '`--page-pool 8` without `--partition virtual`' "$gnomon" render --page-pool 8 --width 64 --height 36 --out r3.png
measure '`calibrate --sweep-depth-bias 0..1:64`' "$gnomon" calibrate --sweep-depth-bias 0..1:64 --out cal3
measure '`calibrate` over 64⁴ points' "$gnomon" calibrate --technique pcf --sweep-depth-bias 0..63:64 \
  --sweep-slope-bias 0..4:64 --sweep-normal-offset 0..2:64 --sweep-kernel 1..9:64 --out cal3
measure '`--out x.png/`' "$gnomon" render --out x.png/
measure '`--out` of a 250-byte name' "$gnomon" render --out "$(printf 'n%.0s' $(seq 246)).png"
mkdir -p aov3 && mkfifo aov3/visibility.npy
measure '`--aov-out` over a FIFO' "$gnomon" render --aov-out aov3 --aov-format npy --out r3.png
mkdir -p probe/model && cp round3/alpha-1.gltf probe/model/
sed 's|"uri": "data:[^"]*"|"uri": "../../passwd"|' probe/model/alpha-1.gltf > probe/model/outside.gltf
sed 's|"uri": "data:[^"]*"|"uri": "../../no-such-file"|' probe/model/alpha-1.gltf > probe/model/missing.gltf
: > passwd
measure 'a URI to an existing file outside the folder' "$gnomon" render probe/model/outside.gltf --out r3.png
measure 'a URI to a missing file outside the folder' "$gnomon" render probe/model/missing.gltf --out r3.png

# The planted links: a link at the name the staging file once had, and in the
# reference cache; a FIFO in the cache; a planted runtime folder.
echo "secret" > victim
sh -c 'ln -s victim .planted.png.gnomon-$$.tmp; exec "$0" render --width 64 --height 36 --out planted.png' "$gnomon" \
  > /dev/null 2>&1
echo "| a link planted at \`.planted.png.gnomon-PID.tmp\` | victim holds \`$(cat victim)\` | planted.png is $( [ -L planted.png ] && echo a link || echo a regular file ) |"
ln -sf victim planted.png
"$gnomon" render --width 64 --height 36 --out planted.png > /dev/null 2>&1
echo "| a link at \`--out planted.png\` | victim holds \`$(cat victim)\` | planted.png is $( [ -L planted.png ] && echo a link || echo a regular file ) |"
mkdir -p cache3
key_file=$(GNOMON_CACHE_DIR=cache3 "$gnomon" compare spheres --width 32 --height 18 --samples 8 \
  --techniques hard --out cmp3 2>&1 > /dev/null; ls cache3)
rm -f "cache3/$key_file" && mkfifo "cache3/$key_file"
measure 'a FIFO where the cache entry is' env GNOMON_CACHE_DIR=cache3 "$gnomon" compare spheres --width 32 --height 18 \
  --samples 8 --techniques hard --out cmp3
mkdir -p runtime-tmp/gnomon-runtime-"$(id -u)" && chmod 777 runtime-tmp/gnomon-runtime-"$(id -u)"
set +e
env -u XDG_RUNTIME_DIR TMPDIR="$work/runtime-tmp" "$gnomon" render --width 64 --height 36 --out rt.png > /dev/null 2>&1
status=$?
set -e
echo "| a world-writable \`\$TMPDIR/gnomon-runtime-UID\` | entries Gnomon made in it: $(ls -A runtime-tmp/gnomon-runtime-"$(id -u)" | wc -l) | exit $status |"
