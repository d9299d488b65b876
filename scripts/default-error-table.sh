#!/bin/sh
# How wrong the defaults are, every pixel counted (issues 22, 25, 48): every public
# glTF scene of ../shared/scenes at its default view under a sun 20°, 45° and 70°
# up, a close view of each (many edges and creases in frame), and the built-in
# scenes at their own and at close views, all with default settings (`pcf2x2`,
# refined by rays where the map is unsure) and with `raytraced` (a ray at every
# pixel), compared by `gnomon compare` against the truth traced from each frame's own
# surfaces (the drawn metric: every light-facing pixel, ambiguous pixels apart) and,
# for the history, against the reference through the pixel centres (silhouettes left
# out). Prints a markdown table and a summary; keeps each case's metrics.json under
# OUT.
#
#   sh scripts/default-error-table.sh [GNOMON] [SHARED_SCENES] [OUT]
#
# CASES (a file of `name|scene|flags` lines, scene relative to SHARED_SCENES or a
# built-in's name) replaces the list below.
set -eu
gnomon=${1:-target/release/gnomon}
shared=${2:-../shared/scenes}
out=${3:-default-errors}
mkdir -p "$out"
if [ -n "${CASES:-}" ]; then
  cases=$(cat "$CASES")
else
  cases=""
  for scene in sponza/sponza_geometry.glb florence/florence.glb etoile/etoile.glb environment/environment.glb \
      tree/tree.glb bunny/bunny.glb dragon/dragon_res3.glb dragon/dragon_res4.glb teapot/teapot.glb \
      monkeyhead/monkeyhead.glb pmndrs/bunny.glb pmndrs/suzi.glb; do
    for elevation in 20 45 70; do
      cases="$cases
$scene, default view, sun $elevation°|$scene|--sun-elevation $elevation"
    done
  done
  cases="$cases
florence, close view (issue 48)|florence/florence.glb|--camera-eye 250,150,350 --camera-target 0,0,0 --fov 50 --sun-elevation 35 --sun-azimuth 40
florence, street level|florence/florence.glb|--camera-eye 30,6,80 --camera-target=-20,10,0 --fov 60
etoile, close view|etoile/etoile.glb|--camera-eye 80,40,80 --camera-target 0,5,0 --fov 50
sponza, the arcades|sponza/sponza_geometry.glb|--camera-eye 0,10,-4 --camera-target 60,20,-50 --fov 50 --sun-elevation 70.17 --sun-azimuth 303.69
environment, among the bamboo|environment/environment.glb|--camera-eye 150,60,150 --camera-target 0,20,0 --fov 50
tree, the leaves|tree/tree.glb|--camera-eye 2.5,3.5,2.5 --camera-target 0,2.8,0 --fov 50
dragon on a ground, close|dragon/dragon_res3.glb|--ground --camera-eye 0.07,0.14,0.12 --camera-target 0,0.11,0 --fov 40
bunny on a ground, close|bunny/bunny.glb|--ground --camera-eye 0.8,0.9,1.6 --camera-target 0,0.4,0 --fov 40
suzi on a ground, close|pmndrs/suzi.glb|--ground --camera-eye 1.2,0.8,1.6 --camera-target 0,0.2,0 --fov 40
spheres|spheres|
spheres, close view|spheres|--camera-eye 3,1.5,4 --camera-target 1,0.5,1 --fov 40
contact|contact|
columns|columns|
columns, close view|columns|--camera-eye 4,2,6 --camera-target 0,1,0 --fov 50
grazing|grazing|"
fi
tsv="$out/cases.tsv"
printf 'case\tdefaults\traytraced\tambiguous\tcamera_rays\tcompared\n' > "$tsv"
echo "| case | defaults | \`raytraced\` | ambiguous | defaults, camera-ray metric | light-facing pixels |"
echo "|---|---|---|---|---|---|"
echo "$cases" | while IFS='|' read -r name scene flags; do
  [ -n "$name" ] || continue
  case "$scene" in *.glb|*.gltf|*.toml) path="$shared/$scene" ;; *) path="$scene" ;; esac
  dir="$out/$(echo "$name" | tr -c 'a-zA-Z0-9\n' '-')"
  # shellcheck disable=SC2086
  if "$gnomon" compare "$path" $flags --techniques pcf2x2,raytraced --timing-frames 1 \
      --out "$dir" > /dev/null 2> "$dir.log"; then
    python3 - "$dir/metrics.json" "$name" "$tsv" <<'PY'
import json, sys
path, name, tsv = sys.argv[1:]
rows = {r["technique"]: r for r in json.load(open(path))["rows"]}
d, t = rows["pcf2x2"]["drawn"], rows["raytraced"]["drawn"]
cells = [name, d["mismatch_rate"], t["mismatch_rate"], d["ambiguous_rate"], rows["pcf2x2"]["mismatch_rate"], d["compared"]]
open(tsv, "a").write("\t".join(map(str, cells)) + "\n")
pct = lambda v: f"{100 * v:.3f} %"
print(f"| {name} | {pct(cells[1])} | {pct(cells[2])} | {pct(cells[3])} | {pct(cells[4])} | {cells[5]} |")
PY
  else
    echo "| $name | error: $(tail -n 1 "$dir.log") | | | | |"
  fi
done
python3 - "$tsv" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
for key, label in (("defaults", "defaults"), ("raytraced", "raytraced"), ("ambiguous", "ambiguous")):
    v = [float(r[key]) for r in rows]
    worst = max(rows, key=lambda r: float(r[key]))
    print(f"\n{label}: median {100 * statistics.median(v):.4f} %, worst {100 * max(v):.4f} % ({worst['case']}), over {len(v)} cases", end="")
print()
PY
