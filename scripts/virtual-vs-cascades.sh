#!/bin/sh
# Issue 53's comparison: a sun's virtual map (`--partition virtual` at its defaults,
# and without its finer pages along shadow edges, `--page-edge-levels 0`, in the
# pool of 24² tiles that was the default before them) against four 2048² cascades,
# at the three views the issue names (Sponza from the Bevy view, Florence's close
# view, the tree with the sun at 45°), in one run on one device:
#   - the error with `--refine off` and with the default refinement, every
#     light-facing pixel counted against the CPU reference, and the share of the
#     screen the default traces (`compare --verbose`);
#   - a moving sun (`bench --sun-path day`): the shadow passes' time and the texels
#     they rasterize per frame, both partitions alternating;
#   - a still sun and camera: the virtual map's kept pages against the cascades
#     redrawn every frame (`--map-cache off`).
# Each command runs under its own time limit; a failed one is written down and does
# not stop the others. Writes OUT/virtual-vs-cascades.md.
#
#   sh scripts/virtual-vs-cascades.sh [GNOMON] [SHARED_SCENES] [OUT]
set -u
g=${1:-target/release/gnomon}
s=${2:-../shared/scenes}
o=${3:-virtual-vs-cascades}
limit=${COMMAND_SECONDS:-120}
mkdir -p "$o"
md=$o/virtual-vs-cascades.md
{
  echo "# Virtual map against 4×2048² cascades ($(date -u '+%Y-%m-%d %H:%M UTC'))"
  echo
  echo "Written by \`sh scripts/virtual-vs-cascades.sh\`. Commit: $(git rev-parse --short HEAD 2>/dev/null || echo unknown)."
  echo
} > "$md"
view() {
  case $1 in
    sponza) echo "$s/sponza/sponza_geometry.glb --camera-eye=-85,12,-4 --camera-target=60,30,-4 --fov 60 --sun-elevation 70.17 --sun-azimuth 303.69";;
    florence) echo "$s/florence/florence.glb --camera-eye 250,150,350 --camera-target 0,0,0 --fov 50 --sun-elevation 35 --sun-azimuth 40";;
    tree) echo "$s/tree/tree.glb --sun-elevation 45";;
  esac
}
partition() {
  case $1 in
    cascades) echo "--partition cascades --shadow-res 2048";;
    virtual) echo "--partition virtual";;
    virtual-no-edges) echo "--partition virtual --page-edge-levels 0 --page-pool 24";;
  esac
}
run() { # name, command...: runs it under the limit, its output in $o/name.log
  name=$1; shift
  timeout "$limit" "$@" > "$o/$name.log" 2>&1
  echo "exit $? ($name)" >> "$md"
}
for v in sponza florence tree; do
  for p in cascades virtual virtual-no-edges; do
    for r in off auto; do
      echo "## $v, $p, refine $r" >> "$md"
      # shellcheck disable=SC2046
      run "$v-$p-$r" "$g" compare $(view $v) $(partition $p) --techniques pcf2x2 --refine $r --verbose \
        --out "$o/$v-$p-$r"
      grep -E "refined by rays|virtual map:" "$o/$v-$p-$r.log" >> "$md"
      cat "$o/$v-$p-$r/metrics.md" >> "$md" 2>/dev/null
    done
  done
  for p in cascades virtual virtual-no-edges; do
    echo "## $v, moving sun, $p" >> "$md"
    # shellcheck disable=SC2046
    run "$v-day-$p" "$g" bench $(view $v) $(partition $p) --techniques pcf2x2 --frames 60 --warmup 10 \
      --sun-path day --verbose --out "$o/$v-day-$p"
    cat "$o/$v-day-$p/bench.md" >> "$md" 2>/dev/null
  done
done
echo "## sponza, still sun: virtual (kept pages), cascades (--map-cache off)" >> "$md"
# shellcheck disable=SC2046
run sponza-still-virtual "$g" bench $(view sponza) $(partition virtual) --techniques pcf2x2 --frames 60 \
  --warmup 10 --out "$o/sponza-still-virtual"
cat "$o/sponza-still-virtual/bench.md" >> "$md" 2>/dev/null
# shellcheck disable=SC2046
run sponza-still-cascades "$g" bench $(view sponza) $(partition cascades) --map-cache off --techniques pcf2x2 \
  --frames 60 --warmup 10 --out "$o/sponza-still-cascades"
cat "$o/sponza-still-cascades/bench.md" >> "$md" 2>/dev/null
echo "done: $md"
