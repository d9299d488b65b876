#!/bin/sh
# Casters thinner than a texel (issue 76): the built-in `wires` (wires, a railing and
# poles 4 mm thick) at its own view, from farther and under its spot, at 640×360, each
# with the defaults, the map alone (`--refine off`) and a ray at every pixel
# (`raytraced`), judged by `gnomon compare` against the truth traced from each frame's
# own surfaces. BEFORE, a second build, adds its defaults as a column. Prints a
# markdown table; keeps each case's metrics under OUT.
#
#   sh scripts/thin-casters-table.sh [GNOMON] [OUT] [BEFORE]
set -eu
gnomon=${1:-target/release/gnomon}
out=${2:-thin-casters}
before=${3:-}
mkdir -p "$out"
# The drawn metric's mismatch of `technique` in a compare run's metrics.md.
mismatch() {
  grep -A3 '^| technique | mismatch | false shadow | false lit | MAE | compared' "$1" | grep "^| $2 " | cut -d'|' -f3 | tr -d ' '
}
printf '| case | defaults |%s map alone | `raytraced` |\n' "${before:+ before this change |}"
printf '|---|---|%s---|---|\n' "${before:+---|}"
printf '%s\n' \
  "wires, its view|" \
  "wires, farther|--camera-eye=-2,9,14 --camera-target=0.5,0,-0.5" \
  "wires, under its spot|--light spot" |
while IFS='|' read -r name flags; do
  dir="$out/$(echo "$name" | tr -c 'a-z0-9\n' '-')"
  # shellcheck disable=SC2086
  "$gnomon" compare wires --techniques pcf2x2,raytraced --width 640 --height 360 $flags --out "$dir" >/dev/null 2>&1
  # shellcheck disable=SC2086
  "$gnomon" compare wires --techniques pcf2x2 --refine off --width 640 --height 360 $flags --out "$dir-alone" >/dev/null 2>&1
  old=""
  if [ -n "$before" ]; then
    # shellcheck disable=SC2086
    "$before" compare wires --techniques pcf2x2 --width 640 --height 360 $flags --out "$dir-before" >/dev/null 2>&1
    old=" $(mismatch "$dir-before/metrics.md" pcf2x2) |"
  fi
  printf '| %s | %s |%s %s | %s |\n' "$name" "$(mismatch "$dir/metrics.md" pcf2x2)" "$old" \
    "$(mismatch "$dir-alone/metrics.md" pcf2x2)" "$(mismatch "$dir/metrics.md" raytraced)"
done
