#!/bin/sh
# Issue 22's error target: every public glTF scene of ../shared/scenes at its default
# view with default settings, under a sun 20°, 45° and 70° up, compared with the
# reference over light-facing pixels. Prints a markdown table (and keeps each run's
# metrics.json under OUT).
#
#   sh scripts/default-error-table.sh [GNOMON] [SHARED_SCENES] [OUT]
set -eu
gnomon=${1:-target/release/gnomon}
shared=${2:-../shared/scenes}
out=${3:-default-errors}
mkdir -p "$out"
scenes="sponza/sponza_geometry.glb florence/florence.glb etoile/etoile.glb environment/environment.glb
tree/tree.glb bunny/bunny.glb dragon/dragon_res3.glb dragon/dragon_res4.glb teapot/teapot.glb
monkeyhead/monkeyhead.glb pmndrs/bunny.glb pmndrs/suzi.glb"
echo "| scene | sun 20° | sun 45° | sun 70° |"
echo "|---|---|---|---|"
for scene in $scenes; do
  name=$(echo "$scene" | tr '/' '-' | sed 's/\.glb$//')
  row="| \`$scene\` |"
  for elevation in 20 45 70; do
    dir="$out/$name-$elevation"
    if "$gnomon" compare "$shared/$scene" --sun-elevation "$elevation" --techniques pcf2x2 \
        --timing-frames 1 --out "$dir" > /dev/null 2> "$dir.log"; then
      cell=$(python3 -c "import json,sys; r=json.load(open('$dir/metrics.json'))['rows'][0]; print('%.3f %% (%d px)' % (100*r['mismatch_rate'], r['compared']))")
    else
      cell="error: $(tail -1 "$dir.log")"
    fi
    row="$row $cell |"
  done
  echo "$row"
done
