#!/bin/sh
# Issue 22's table for choosing the defaults of a sun on glTF scenes: every candidate
# setting below on every public glTF scene of ../shared/scenes, at its default view,
# under a sun 20°, 45° and 70° up, compared with the reference over light-facing
# pixels. Writes OUT/cases.tsv (one line per candidate, scene and elevation) and
# prints a markdown summary per candidate: the median and worst share of light-facing
# pixels wrong, the cases above issue 22's 0.3 %, and the median GPU time of the
# shadow and lighting passes. Candidates are measured with --refine off unless their
# flags name --refine.
#
#   sh scripts/defaults-table.sh [GNOMON] [SHARED_SCENES] [OUT]
#
# SCENES (paths under SHARED_SCENES, space-separated) and CANDIDATES (a file of
# `name|flags` lines) override the lists below; TIMING_FRAMES (default 3) sets the
# frames each case is timed over.
set -eu
gnomon=${1:-target/release/gnomon}
shared=${2:-../shared/scenes}
out=${3:-defaults-table}
mkdir -p "$out"
scenes=${SCENES:-"sponza/sponza_geometry.glb florence/florence.glb etoile/etoile.glb environment/environment.glb
tree/tree.glb bunny/bunny.glb dragon/dragon_res3.glb dragon/dragon_res4.glb teapot/teapot.glb
monkeyhead/monkeyhead.glb pmndrs/bunny.glb pmndrs/suzi.glb"}
if [ -n "${CANDIDATES:-}" ]; then
  candidates=$(cat "$CANDIDATES")
else
  # Round one: one change at a time from the old defaults (normal offset 0.6).
  candidates="old defaults (slope 1.5, normal offset 0.6)|--normal-offset 0.6
normal offset 0.3|--normal-offset 0.3
normal offset 0|--normal-offset 0
slope 1, normal offset 0.3|--slope-bias 1 --normal-offset 0.3
slope 2, normal offset 0|--slope-bias 2 --normal-offset 0
hard|--techniques hard --normal-offset 0.6
pcf 3×3|--techniques pcf --pcf-kernel 3 --normal-offset 0.6
map 4096²|--shadow-res 4096 --normal-offset 0.6
4 stable cascades|--partition cascades --normal-offset 0.6
4 tight cascades, SDSM bounds|--partition cascades --cascade-fit tight --sdsm --sdsm-bounds --normal-offset 0.6"
fi
tsv="$out/cases.tsv"
printf 'candidate\tscene\televation\tmismatch\tfalse_shadow\tfalse_lit\tcompared\tshadow_ms\tlighting_ms\n' > "$tsv"
echo "$candidates" | while IFS='|' read -r name flags; do
  [ -n "$name" ] || continue
  for scene in $scenes; do
    for elevation in 20 45 70; do
      dir="$out/run"
      rm -rf "$dir"
      # The default technique, unless the candidate names its own. The candidates
      # choose the map's settings, so they are measured unrefined unless they name
      # --refine (the default refines by rays, which hides most of what they change).
      case "$flags" in *--techniques*) technique= ;; *) technique="--techniques pcf2x2" ;; esac
      case "$flags" in *--refine*) refine= ;; *) refine="--refine off" ;; esac
      # shellcheck disable=SC2086
      if "$gnomon" compare "$shared/$scene" --sun-elevation "$elevation" $technique \
          --timing-frames "${TIMING_FRAMES:-3}" --out "$dir" $refine $flags > /dev/null 2> "$out/last.log"; then
        python3 - "$dir/metrics.json" "$name" "$scene" "$elevation" >> "$tsv" <<'PY'
import json, sys
path, name, scene, elevation = sys.argv[1:]
r = json.load(open(path))["rows"][0]
print("\t".join(map(str, [name, scene, elevation, r["mismatch_rate"], r["false_shadow_rate"],
      r["false_lit_rate"], r["compared"], r["shadow_ms"], r["lighting_ms"]])))
PY
      else
        echo "gnomon failed on $scene at $elevation° with '$name': $(tail -1 "$out/last.log")" >&2
        exit 1
      fi
    done
  done
done
python3 - "$tsv" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
names = list(dict.fromkeys(r["candidate"] for r in rows))
print("| candidate | median wrong | worst | cases > 0.3 % | shadow pass ms | lighting pass ms |")
print("|---|---|---|---|---|---|")
for name in names:
    mine = [r for r in rows if r["candidate"] == name]
    wrong = [float(r["mismatch"]) for r in mine]
    worst = max(mine, key=lambda r: float(r["mismatch"]))
    ms = lambda key: statistics.median(float(r[key]) for r in mine if r[key] not in ("", "None"))
    print(f"| {name} | {100 * statistics.median(wrong):.3f} % | {100 * max(wrong):.2f} % "
          f"(`{worst['scene']}`, {worst['elevation']}°) | {sum(w > 0.003 for w in wrong)} of {len(wrong)} "
          f"| {ms('shadow_ms'):.1f} | {ms('lighting_ms'):.1f} |")
PY
