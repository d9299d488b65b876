#!/bin/sh
# The cost of following moved casters (`Renderer::move_instances`): `gnomon bench
# --moving N --refine rays` on the built-in `instances` scene, Florence and Sponza
# (from ../shared/scenes, skipped where absent), one instance moving and every
# instance moving. Prints a markdown table of `CPU move` (median and p95) against the
# time to build the casters' BVH afresh; the runs stay under OUT.
#
#   sh scripts/moving-table.sh [GNOMON] [OUT] [SHARED_SCENES]
set -eu
gnomon=${1:-target/release/gnomon}
out=${2:-moving-table}
shared=${3:-../shared/scenes}
mkdir -p "$out"
echo "| scene | instances (triangles) | moving | CPU move, ms: median (p95) | BVH built afresh, ms | GPU frame, ms |"
echo "|---|---|---|---|---|---|"
for scene in instances:10000 "$shared/florence/florence.glb" "$shared/sponza/sponza_geometry.glb"; do
  case "$scene" in
    *.glb) [ -f "$scene" ] || { echo "skipping $scene: not found" >&2; continue; } ;;
  esac
  name=$(basename "$scene" .glb | tr ':' '-')
  for moving in 1 all; do
    if [ "$moving" = all ]; then
      # Every instance with triangles: the count the bench's own error names.
      count=$("$gnomon" bench "$scene" --moving 0 --out "$out/probe" 2>&1 | sed -n 's/.*give 1 to \([0-9]*\).*/\1/p')
      # A scene of one instance has its row already.
      [ "$count" -gt 1 ] || continue
    else
      count=1
    fi
    echo "gnomon bench $scene --moving $count --refine rays --width 960 --height 540" >&2
    "$gnomon" bench "$scene" --moving "$count" --refine rays --width 960 --height 540 --frames 20 --warmup 3 \
      --out "$out/$name-$moving" > /dev/null 2> "$out/$name-$moving.log" || { tail -5 "$out/$name-$moving.log" >&2; exit 1; }
    python3 - "$out/$name-$moving/bench.json" "$count" <<'PY'
import json, sys
report = json.load(open(sys.argv[1]))
config = report["configs"][0]
passes = {p["name"]: p for p in config["passes"]}
move, frame = passes["CPU move"], passes["GPU frame"]
print(f"| `{report['scene']}` | {report['instances']} ({report['triangles']}) | {sys.argv[2]} "
      f"| {move['median_ms']:.2f} ({move['p95_ms']:.2f}) | {report['rebuild_ms']:.1f} | {frame['median_ms']:.0f} |")
PY
  done
done
