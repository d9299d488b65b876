#!/bin/sh
# The hard cases of issue 76, every pixel counted: casters thinner than a texel
# (`wires`), a street canyon under low suns (`canyon`), dense scans on a ground under
# a grazing and a high sun (the shared Stanford dragon and bunny, where ../shared is
# present), and a finely tessellated ball under a sun 4° up. Each case is rendered at
# the defaults, with `raytraced` (a ray at every pixel), and by three maps alone
# (`--refine off`): the default single 2048² map, a single map of the virtual pool's
# memory (4096², 16.8 M texels) and the virtual map; `gnomon compare` judges each
# against the truth traced from its own surfaces (the drawn metric: every
# light-facing pixel; ambiguous pixels apart). Prints a markdown table and each
# column's median and worst case; keeps each case's metrics.json under OUT.
#
#   sh scripts/hard-cases-table.sh [GNOMON] [SHARED_SCENES] [OUT]
#
# CASES (a file of `name|scene|flags` lines, scene relative to SHARED_SCENES or a
# built-in's name) replaces the list below.
set -eu
gnomon=${1:-target/release/gnomon}
shared=${2:-../shared/scenes}
out=${3:-hard-cases}
mkdir -p "$out"
if [ -n "${CASES:-}" ]; then
  cases=$(cat "$CASES")
else
  cases="wires, sun 50°, close|wires|
wires, sun 50°, far|wires|--camera-eye=-2,9,14 --camera-target 0.5,0,-0.5
wires, sun 20°|wires|--sun-elevation 20 --sun-azimuth 75
canyon, sun 15° at 20° (its own)|canyon|
canyon, sun 10° at 0°|canyon|--sun-elevation 10 --sun-azimuth 0
canyon, sun 20° at 340°|canyon|--sun-elevation 20 --sun-azimuth 340
canyon, sun 15° at 45°|canyon|--sun-elevation 15 --sun-azimuth 45
spheres, close, sun 4°|spheres|--camera-eye 3,1.5,4 --camera-target 1,0.5,1 --fov 40 --sun-elevation 4 --sun-azimuth 30"
  if [ -d "$shared/dragon" ]; then
    cases="$cases
dragon on a ground, close, sun 40°|dragon/dragon_res3.glb|--ground --camera-eye 0.07,0.14,0.12 --camera-target 0,0.11,0 --fov 40 --sun-elevation 40
dragon on a ground, close, sun 8°|dragon/dragon_res3.glb|--ground --camera-eye 0.07,0.14,0.12 --camera-target 0,0.11,0 --fov 40 --sun-elevation 8
bunny on a ground, close, sun 8°|bunny/bunny.glb|--ground --camera-eye 0.8,0.9,1.6 --camera-target 0,0.4,0 --fov 40 --sun-elevation 8"
  fi
fi
tsv="$out/cases.tsv"
printf 'case\tdefaults\traytraced\tsingle\tsingle_pool\tvirtual\tambiguous\tcompared\n' > "$tsv"
echo "| case | defaults | \`raytraced\` | single 2048² alone | single 4096² alone | virtual alone | ambiguous | light-facing pixels |"
echo "|---|---|---|---|---|---|---|---|"
echo "$cases" | while IFS='|' read -r name scene flags; do
  [ -n "$name" ] || continue
  case "$scene" in *.glb|*.gltf|*.toml) path="$shared/$scene" ;; *) path="$scene" ;; esac
  dir="$out/$(echo "$name" | tr -c 'a-zA-Z0-9\n' '-')"
  mkdir -p "$dir"
  failed=""
  for run in "defaults|--techniques pcf2x2,raytraced" "single|--techniques pcf2x2 --refine off" \
      "single_pool|--techniques pcf2x2 --refine off --shadow-res 4096" \
      "virtual|--techniques pcf2x2 --refine off --partition virtual"; do
    tag=${run%%|*}
    # shellcheck disable=SC2086
    "$gnomon" compare "$path" $flags ${run#*|} --timing-frames 1 --out "$dir/$tag" > /dev/null 2> "$dir-$tag.log" \
      || failed="$tag: $(tail -n 1 "$dir-$tag.log")"
  done
  if [ -n "$failed" ]; then
    echo "| $name | error: $failed | | | | | | |"
    continue
  fi
  python3 - "$dir" "$name" "$tsv" <<'PY'
import json, sys
dir, name, tsv = sys.argv[1:]
def drawn(tag):
    return {r["technique"]: r["drawn"] for r in json.load(open(f"{dir}/{tag}/metrics.json"))["rows"]}
defaults = drawn("defaults")
d = defaults["pcf2x2"]
cells = [name, d["mismatch_rate"], defaults["raytraced"]["mismatch_rate"],
         drawn("single")["pcf2x2"]["mismatch_rate"], drawn("single_pool")["pcf2x2"]["mismatch_rate"],
         drawn("virtual")["pcf2x2"]["mismatch_rate"], d["ambiguous_rate"], d["compared"]]
open(tsv, "a").write("\t".join(map(str, cells)) + "\n")
pct = lambda v: f"{100 * v:.3f} %"
print(f"| {name} | " + " | ".join(pct(v) for v in cells[1:7]) + f" | {cells[7]} |")
PY
done
python3 - "$tsv" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
for key in ("defaults", "raytraced", "single", "single_pool", "virtual"):
    v = [float(r[key]) for r in rows]
    worst = max(rows, key=lambda r: float(r[key]))
    print(f"\n{key}: median {100 * statistics.median(v):.4f} %, worst {100 * max(v):.4f} % ({worst['case']}), over {len(v)} cases", end="")
worse = [r["case"] for r in rows if float(r["virtual"]) > float(r["single_pool"])]
print(f"\nthe virtual map alone worse than the single map of its memory: {len(worse)} of {len(rows)} cases {worse}")
PY
