#!/bin/sh
# Issue 25's soft-shadow table: PCSS alone, PCSS with its penumbrae refined by rays
# (--penumbra-rays, 16 by default) and every pixel traced, against the Monte Carlo
# area-light reference, in the three area-light configurations of the README's soft
# table; then each one's GPU frame time (`gnomon bench`, median) with and without
# refinement. Prints the README's markdown table; the runs stay under OUT.
#
#   sh scripts/refined-penumbra-table.sh [GNOMON] [OUT] [REFERENCE_SAMPLES]
set -eu
gnomon=${1:-target/release/gnomon}
out=${2:-refined-penumbra-table}
samples=${3:-4096}
mkdir -p "$out"
configs="spheres|spheres --light spot --spot-radius 0.3
contact|contact --light spot --spot-radius 0.5
grazing|grazing --sun-angular-diameter 2"
echo "$configs" | while IFS='|' read -r name args; do
  for refine in off rays every-pixel; do
    echo "gnomon compare $args --techniques pcss --refine $refine --samples $samples --width 960 --height 540" >&2
    # shellcheck disable=SC2086
    "$gnomon" compare $args --techniques pcss --refine "$refine" --samples "$samples" --width 960 --height 540 \
      --out "$out/$name-$refine" > /dev/null 2> "$out/$name-$refine.log" || { tail -5 "$out/$name-$refine.log" >&2; exit 1; }
  done
  echo "gnomon bench $args --technique pcss --sweep refine=off,rays,every-pixel --width 960 --height 540" >&2
  # shellcheck disable=SC2086
  "$gnomon" bench $args --technique pcss --sweep refine=off,rays,every-pixel --width 960 --height 540 \
    --frames 5 --warmup 2 --out "$out/$name-bench" > /dev/null 2> "$out/$name-bench.log" \
    || { tail -5 "$out/$name-bench.log" >&2; exit 1; }
done
python3 - "$out" "$samples" <<'PY'
import json, sys
out, samples = sys.argv[1], sys.argv[2]
configs = [("spheres", "`spheres`, spot r 0.3 m"), ("contact", "`contact`, spot r 0.5 m"), ("grazing", "`grazing`, sun 2°")]
def penumbra(name, refine):
    row = json.load(open(f"{out}/{name}-{refine}/metrics.json"))["rows"][0]
    return row["penumbra"]
def frame(name):
    bench = json.load(open(f"{out}/{name}-bench/bench.json"))
    rows = {c["sweep_value"]: c for c in bench["configs"]}
    ms = lambda c: next(p["median_ms"] for p in c["passes"] if p["name"] == "GPU frame")
    return {k: (ms(c), c.get("traced_percent"), c.get("rays")) for k, c in rows.items()}
print(f"| configuration | PCSS alone: penumbra MAE | refined, 16 rays: penumbra MAE (÷ PCSS) | every pixel, 16 rays | width error (bias), px: alone → refined | traced, % of screen (rays) | GPU frame, ms: alone (forward) → refined → every pixel |")
print("|---|---|---|---|---|---|---|")
for name, label in configs:
    alone, refined, every = (penumbra(name, r) for r in ("off", "rays", "every-pixel"))
    f = frame(name)
    w = lambda p: "n/a" if p["width"]["error_px"] is None else f"{p['width']['error_px']:.1f} ({p['width']['bias_px']:+.1f})"
    _, percent, rays = f["rays"]
    print(f"| {label} | {alone['mae']:.4f} | **{refined['mae']:.4f}** ({refined['mae'] / alone['mae']:.2f}) | {every['mae']:.4f} | "
          f"{w(alone)} → {w(refined)} | {percent:.2f} ({rays}) | {f['off'][0]:.0f} → {f['rays'][0]:.0f} → {f['every-pixel'][0]:.0f} |")
print()
print(f"Reference: {samples} rays per pixel; penumbra pixels: " + ", ".join(f"{penumbra(n, 'off')['pixels']} ({n})" for n, _ in configs))
PY
