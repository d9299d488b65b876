#!/usr/bin/env bash
# Renders the visibility of every technique on a fixed set of scenes into DIR, one
# `.npy` per (scene, technique): the "before" or "after" side of a refactor that must
# not change what is drawn. Compare two dumps with scripts/visibility-diff.py.
#
#   scripts/visibility-dump.sh target/release/gnomon /tmp/before [SPONZA.glb]
set -uo pipefail
gnomon="$1"; out="$2"; sponza="${3:-../shared/scenes/sponza/sponza_geometry.glb}"
mkdir -p "$out"
techniques="hard pcf2x2 pcf pcf-tent pcf-poisson pcss vsm esm evsm2 evsm4 msm-hamburger msm-hausdorff convolution"
scenes=("spheres" "contact" "columns" "lamps --light all" "$sponza")
names=("spheres" "contact" "columns" "lamps-all" "sponza")
for i in "${!scenes[@]}"; do
  for t in $techniques; do
    name="${names[$i]}-$t"
    # shellcheck disable=SC2086
    if ! "$gnomon" render ${scenes[$i]} --technique "$t" --width 480 --height 270 \
        --out "$out/$name.png" --visibility-out "$out/$name.npy" 2> "$out/$name.err"; then
      echo "$name: failed ($(head -c 200 "$out/$name.err"))"
    fi
  done
done
