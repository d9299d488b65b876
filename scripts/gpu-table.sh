#!/bin/sh
# The real-GPU table: what lavapipe cannot tell, measured on a lent GPU machine in
# one short run (under 8 minutes on an H100/H200), written as one markdown file.
#
#   sh scripts/gpu-table.sh [GNOMON] [SHARED_SCENES] [OUT]
#
# GNOMON is a release binary (default target/release/gnomon), SHARED_SCENES the
# folder of ../shared/scenes (Sponza, Florence and the other glTF scenes), OUT the
# folder for OUT/gpu-table.md and each command's raw output. Each section runs under
# its own time limit (SECTION_SECONDS, default 90), and the whole run stops starting
# new ones after TOTAL_SECONDS (default 420). A failed, slow or skipped section is
# written down as such and does not stop the others: the run is one lease of a
# machine that may not come again.
#
# Sections, most wanted first:
#   1. the adapter, and the tracer that `--tracer auto` picks on it;
#   2. the defaults table: every shared glTF scene at its default view, a sun at 45°,
#      default settings, compared with the ray-traced reference;
#   3. refinement's cost: `--refine off` against the default on spheres, Sponza and
#      Florence;
#   4. cost per pass of every technique on `spheres`, and on Sponza with the
#      depth-only baseline;
#   5. Sponza from the Bevy comparison's view: instances against clusters, kept maps
#      against none, and Florence's submission paths;
#   6. a moving sun (`bench --sun-path day`, nothing kept) against a still one, kept
#      maps and none, on Sponza from the Bevy view: the shadow passes' time and the
#      texels they rasterize per frame (issue 53's baseline for virtual maps);
#   7. `lamps:N`: lighting per light with the light list;
#   8. virtual maps against cascades (`scripts/virtual-vs-cascades.sh`, its own
#      limit of VIRTUAL_SECONDS, default 240): error, traced share, moving and
#      still sun at the three views of issue 53;
#   9. a sweeping spot (`bench --spot-path sweep`): its 2D map against its virtual
#      map, the shadow passes' time and texels;
#  10. a swaying point light (`bench --point-path sway`): its cube map against its
#      virtual map, the same.
set -u
gnomon=${1:-target/release/gnomon}
shared=${2:-../shared/scenes}
out=${3:-gpu-table}
section_limit=${SECTION_SECONDS:-90}
deadline=$(( $(date +%s) + ${TOTAL_SECONDS:-420} ))
mkdir -p "$out"
md="$out/gpu-table.md"
sponza="$shared/sponza/sponza_geometry.glb"
florence="$shared/florence/florence.glb"
bevy_view="--camera-eye=-85,12,-4 --camera-target=60,30,-4 --fov 60 --sun-elevation 70.17 --sun-azimuth 303.69 --partition cascades --shadow-res 2048"

{
  echo "# Gnomon on a real GPU"
  echo
  echo "Written by \`sh scripts/gpu-table.sh\` on $(date -u '+%Y-%m-%d %H:%M UTC')."
  echo "Commit: $(git rev-parse --short HEAD 2>/dev/null || echo unknown)."
  echo
} > "$md"

# budget: set $limit to the seconds a section may take now (the section limit, or
# what is left of the whole run); false when nothing is left.
budget() {
  left=$(( deadline - $(date +%s) ))
  limit=$section_limit
  [ "$left" -lt "$limit" ] && limit=$left
  [ "$limit" -gt 5 ]
}

# step NAME COMMAND...: run COMMAND under the section limit, keep its output in
# OUT/NAME.log, and copy it into the markdown file as a fenced block.
step() {
  name=$1
  shift
  if ! budget; then
    printf '### %s\n\nskipped: the run is out of time.\n\n' "$name" >> "$md"
    return
  fi
  start=$(date +%s)
  timeout "$limit" "$@" > "$out/$name.log" 2>&1
  status=$?
  seconds=$(( $(date +%s) - start ))
  {
    echo "### $name"
    echo
    echo "\`$*\` (exit $status, ${seconds} s)"
    echo
    echo '```text'
    # The tables bench prints, without its progress bars.
    grep -v '\[.*\] *[0-9]*/[0-9]*' "$out/$name.log" | tail -n 80
    echo '```'
    echo
  } >> "$md"
}

# bench_md NAME: append the markdown report bench wrote into OUT/NAME/.
bench_md() {
  if [ -f "$out/$1/bench.md" ]; then
    { echo "#### $1: bench.md"; echo; cat "$out/$1/bench.md"; echo; } >> "$md"
  fi
}

echo "## 1. The adapter and the tracer" >> "$md"
if command -v nvidia-smi > /dev/null; then
  step nvidia-smi nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv
fi
step adapter "$gnomon" render spheres --verbose --out "$out/spheres.png"
step tracer-auto "$gnomon" render "$sponza" --verbose --tracer auto --out "$out/sponza.png"
step tracer-ray-query "$gnomon" render "$sponza" --verbose --tracer ray-query --out "$out/sponza-rq.png"

echo "## 2. The defaults table (sun 45°, default settings)" >> "$md"
{
  echo
  echo "| scene | defaults, every drawn pixel | \`raytraced\` | ambiguous | defaults, pixel-centre metric | light-facing pixels | lighting ms |"
  echo "|---|---|---|---|---|---|---|"
} >> "$md"
for scene in sponza/sponza_geometry.glb florence/florence.glb etoile/etoile.glb \
    environment/environment.glb tree/tree.glb bunny/bunny.glb dragon/dragon_res3.glb \
    dragon/dragon_res4.glb teapot/teapot.glb monkeyhead/monkeyhead.glb pmndrs/bunny.glb \
    pmndrs/suzi.glb; do
  name=$(echo "$scene" | tr '/' '-' | sed 's/\.glb$//')
  dir="$out/defaults-$name"
  if ! budget; then
    echo "| \`$scene\` | skipped: the run is out of time | | | | | |" >> "$md"
    continue
  fi
  if timeout "$limit" "$gnomon" compare "$shared/$scene" --sun-elevation 45 --techniques pcf2x2,raytraced \
      --timing-frames 5 --out "$dir" > "$dir.log" 2>&1; then
    python3 - "$dir/metrics.json" "$scene" >> "$md" <<'PY'
import json, sys
rows = json.load(open(sys.argv[1]))["rows"]
r, traced = rows[0], rows[1]
pct = lambda v: f"{100 * v:.3f} %"
ms = lambda v: "–" if v is None else f"{v:.2f}"
print(f"| `{sys.argv[2]}` | {pct(r['drawn']['mismatch_rate'])} | {pct(traced['drawn']['mismatch_rate'])} "
      f"| {pct(r['drawn']['ambiguous_rate'])} | {pct(r['mismatch_rate'])} | {r['drawn']['compared']} | {ms(r.get('lighting_ms'))} |")
PY
  else
    echo "| \`$scene\` | failed: $(tail -n 1 "$dir.log") | | | | | |" >> "$md"
  fi
done
echo >> "$md"
# Issue 48's close view of Florence, many edges in frame.
step florence-close "$gnomon" compare "$florence" --camera-eye 250,150,350 --camera-target 0,0,0 \
  --fov 50 --sun-elevation 35 --sun-azimuth 40 --techniques pcf2x2,raytraced --timing-frames 5 \
  --out "$out/florence-close"
[ -f "$out/florence-close/metrics.md" ] && cat "$out/florence-close/metrics.md" >> "$md"

echo "## 3. Refinement's cost (--refine off against the default)" >> "$md"
step refine-spheres "$gnomon" bench spheres --techniques pcf2x2 --frames 60 --warmup 10 \
  --map-cache off --sweep refine=off,auto --out "$out/refine-spheres"
bench_md refine-spheres
# shellcheck disable=SC2086
step refine-sponza "$gnomon" bench "$sponza" --techniques pcf2x2 --frames 60 --warmup 10 \
  --map-cache off --sweep refine=off,auto --out "$out/refine-sponza" $bevy_view
bench_md refine-sponza
step refine-florence "$gnomon" bench "$florence" --techniques pcf2x2 --frames 60 --warmup 10 \
  --map-cache off --sweep refine=off,auto --out "$out/refine-florence"
bench_md refine-florence

echo "## 4. Cost per pass" >> "$md"
all=hard,pcf2x2,pcf,pcf-tent,pcf-poisson,pcss,vsm,esm,evsm2,evsm4,msm-hamburger,msm-hausdorff,convolution
# Every layer drawn every frame (--map-cache off), as under a moving light: a kept map
# would draw nothing.
step cost-spheres "$gnomon" bench spheres --techniques "$all" --frames 60 --warmup 10 \
  --refine off --map-cache off --out "$out/cost-spheres"
bench_md cost-spheres
step cost-sponza "$gnomon" bench "$sponza" --techniques "$all" --frames 60 --warmup 10 \
  --refine off --map-cache off --depth-only --out "$out/cost-sponza"
bench_md cost-sponza

echo "## 5. Sponza from the Bevy comparison's view, and Florence's submission" >> "$md"
# shellcheck disable=SC2086
step bevy-view-culling "$gnomon" bench "$sponza" $bevy_view --techniques pcf2x2 --frames 60 \
  --warmup 10 --map-cache off --sweep caster-culling=instances,clusters,instances,clusters \
  --out "$out/bevy-view-culling"
bench_md bevy-view-culling
# shellcheck disable=SC2086
step bevy-view-dolly "$gnomon" bench "$sponza" $bevy_view --techniques pcf2x2 --frames 60 \
  --warmup 10 --camera-path dolly --sweep map-cache=off,still-casters,off,still-casters \
  --out "$out/bevy-view-dolly"
bench_md bevy-view-dolly
step florence-submission "$gnomon" bench "$florence" --partition cascades --techniques pcf2x2 \
  --frames 60 --warmup 10 --map-cache off \
  --sweep draw-submission=direct,indirect,gpu-culled,direct,indirect,gpu-culled \
  --out "$out/florence-submission"
bench_md florence-submission

echo "## 6. A moving sun against a still one (Sponza, the Bevy view)" >> "$md"
# The sun moves every frame along a day's arc: no kept map is valid, every layer is
# drawn, whatever --map-cache says. Still sun: kept maps draw nothing.
# shellcheck disable=SC2086
step sun-day "$gnomon" bench "$sponza" $bevy_view --techniques pcf2x2 --frames 60 --warmup 10 \
  --sun-path day --sweep map-cache=still-casters,off --out "$out/sun-day"
bench_md sun-day
# shellcheck disable=SC2086
step sun-still "$gnomon" bench "$sponza" $bevy_view --techniques pcf2x2 --frames 60 --warmup 10 \
  --sweep map-cache=still-casters,off --out "$out/sun-still"
bench_md sun-still

echo "## 7. lamps:N, the light list" >> "$md"
for n in 1 8 32 64; do
  step "lamps-$n" "$gnomon" bench "lamps:$n" --light all --frames 30 --warmup 5 \
    --sweep lighting=light-list,per-light --out "$out/lamps-$n"
  bench_md "lamps-$n"
done

echo "## 8. Virtual map against cascades" >> "$md"
if [ "$(date +%s)" -lt "$deadline" ]; then
  timeout "${VIRTUAL_SECONDS:-240}" sh "$(dirname "$0")/virtual-vs-cascades.sh" "$gnomon" "$shared" "$out/virtual" \
    > "$out/virtual.log" 2>&1
  echo "exit $?" >> "$md"
  cat "$out/virtual/virtual-vs-cascades.md" >> "$md" 2>/dev/null
else
  printf 'skipped: the run is out of time.\n\n' >> "$md"
fi
echo "## 9. A sweeping spot: its 2D map against its virtual map (contact)" >> "$md"
step spot-sweep "$gnomon" bench contact --light spot --spot-path sweep --techniques pcf2x2 \
  --frames 60 --warmup 10 --width 1280 --height 720 --sweep partition=single,virtual --out "$out/spot-sweep"
bench_md spot-sweep
echo "## 10. A swaying point light: its cube map against its virtual map (contact)" >> "$md"
step point-sway "$gnomon" bench contact --light point --point-path sway --techniques pcf2x2 \
  --frames 60 --warmup 10 --width 1280 --height 720 --sweep partition=single,virtual --out "$out/point-sway"
bench_md point-sway
echo "done: $md"
