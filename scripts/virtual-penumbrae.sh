#!/bin/sh
# A sun with an angular size on a virtual map, refined by rays (`--refine rays`):
# the share of the screen traced, and the error against the Monte Carlo reference
# (every light-facing pixel, and the penumbra alone), for the virtual map refined
# where its footprint test and its search over the sun's cone are unsure, every
# pixel traced (what a virtual map did before that search), and four cascades
# refined by the same search. PCSS, 320×180, 128 reference rays a pixel. Prints a
# markdown table.
#
#   sh scripts/virtual-penumbrae.sh [GNOMON]
set -eu
g=${1:-target/release/gnomon}
echo "| scene, sun | map, refinement | traced, % of screen | MAE, all | MAE, penumbra |"
echo "|---|---|---|---|---|"
out=$(mktemp -d)
for scene in grazing contact columns; do
  for degrees in 3 10; do
    for config in "virtual rays" "virtual every-pixel" "cascades rays" "single rays"; do
      set -- $config
      flags="$scene --partition $1 --refine $2 --sun-angular-diameter $degrees --width 320 --height 180"
      # shellcheck disable=SC2086
      traced=$("$g" render $flags --technique pcss --verbose --out "$out/render.png" 2>&1 |
        sed -n 's/.*refined by rays at [0-9]* pixels, \([0-9.]*\) %.*/\1/p')
      # shellcheck disable=SC2086
      "$g" compare $flags --techniques pcss --samples 128 --out "$out/compare" > /dev/null 2>&1
      errors=$(python3 -c "import json,sys; r=json.load(open(sys.argv[1]))['rows'][0]; print('%.4f | %.4f' % (r['mae'], r['penumbra']['mae']))" "$out/compare/metrics.json")
      echo "| $scene, $degrees° | $1, $2 | $traced % | $errors |"
    done
  done
done
rm -rf "$out"
