#!/bin/sh
# Issue 74's cost table: the GPU frame with a light's size given and nothing else
# (`--refine auto`, which beams an area light's unsure penumbrae) over PCSS alone's
# (`--refine off`), in one `gnomon bench` run per case that alternates the two rows.
# Prints a markdown table; each run's bench.md stays under OUT.
#
#   sh scripts/soft-defaults-cost.sh [GNOMON] [OUT]
set -eu
gnomon=${1:-target/release/gnomon}
out=${2:-soft-defaults-cost}
mkdir -p "$out"
run() {
  name=$1
  shift
  (cd "$out" && mkdir -p "$name" && cd "$name" &&
    "$gnomon" bench "$@" --techniques pcss --sweep refine=off,auto --frames 30 --warmup 5 \
      --width 640 --height 360 > bench.log 2>&1) || { tail -5 "$out/$name/bench.log" >&2; exit 1; }
}
run spheres-spot spheres --light spot --spot-radius 0.3
run contact-spot contact --light spot --spot-radius 0.5
run grazing-sun grazing --sun-angular-diameter 2
run spheres-point spheres --light point --point-radius 0.3
python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
print("| case | PCSS alone, GPU frame ms | the defaults, ms | ratio | beamed this frame, % of screen |")
print("|---|---|---|---|---|")
for name in ["spheres-spot", "contact-spot", "grazing-sun", "spheres-point"]:
    configs = json.load(open(f"{out}/{name}/bench/bench.json"))["configs"]
    def frame(config):
        return next(p["median_ms"] for p in config["passes"] if p["name"] == "GPU frame")
    off, auto = (next(c for c in configs if c["sweep_value"] == v) for v in ("off", "auto"))
    beamed = auto["traced_percent"]
    print(f"| {name} | {frame(off):.1f} | {frame(auto):.1f} | {frame(auto) / frame(off):.2f}× | {beamed:.2f} |")
PY
