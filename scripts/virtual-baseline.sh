#!/bin/sh
# Issue 53's cascades baseline, what virtual shadow maps must beat, at the three
# views the issue names (Sponza from the Bevy view, Florence's close view, the tree
# at its default view with the sun at 45°): the error of 4×2048² cascades with
# `--refine off` and with the default refinement (every pixel counted, against the
# CPU reference), and a moving sun's cost (`bench --sun-path day`), as one markdown
# file. About a minute on an H200 machine (16 cores for the reference).
#
#   sh scripts/virtual-baseline.sh [GNOMON] [SHARED_SCENES] [OUT]
set -u
g=${1:-target/release/gnomon}
s=${2:-../shared/scenes}
o=${3:-virtual-baseline}
mkdir -p "$o"
md=$o/baseline.md
echo "# Cascades baseline for virtual maps ($(date -u '+%Y-%m-%d %H:%M UTC'))" > "$md"
view() {
  case $1 in
    sponza) echo "$s/sponza/sponza_geometry.glb --camera-eye=-85,12,-4 --camera-target=60,30,-4 --fov 60 --sun-elevation 70.17 --sun-azimuth 303.69";;
    florence) echo "$s/florence/florence.glb --camera-eye 250,150,350 --camera-target 0,0,0 --fov 50 --sun-elevation 35 --sun-azimuth 40";;
    tree) echo "$s/tree/tree.glb --sun-elevation 45";;
  esac
}
for v in sponza florence tree; do
  for r in off auto; do
    echo "## $v, cascades 4×2048², refine $r" >> "$md"
    # shellcheck disable=SC2046
    timeout 120 "$g" compare $(view $v) --partition cascades --shadow-res 2048 --techniques pcf2x2 \
      --refine $r --verbose --out "$o/$v-$r" > "$o/$v-$r.log" 2>&1
    echo "exit $?" >> "$md"
    cat "$o/$v-$r/metrics.md" >> "$md" 2>/dev/null
  done
  echo "## $v, moving sun, cascades 4×2048²" >> "$md"
  # shellcheck disable=SC2046
  timeout 120 "$g" bench $(view $v) --partition cascades --shadow-res 2048 --techniques pcf2x2 --frames 60 \
    --warmup 10 --sun-path day --out "$o/$v-day" > "$o/$v-day.log" 2>&1
  echo "exit $?" >> "$md"
  cat "$o/$v-day/bench.md" >> "$md" 2>/dev/null
done
echo "done: $md"
