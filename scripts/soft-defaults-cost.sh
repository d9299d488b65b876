#!/bin/sh
# Issue 74's cost table: the GPU frame with a light's size given and nothing else
# (`--refine auto`, which beams an area light's unsure penumbrae) over PCSS alone's
# (`--refine off`), each pair timed one after the other in one `gnomon bench` run.
# Three runs a case, because the beams' cost depends on what the penumbra history
# holds:
#   gathering: a still view's first 16 frames (each beams a quarter of its unsure
#              pixels; the 16th holds four beams each, `--penumbra-frames`' default);
#   settled:   the same view's frames 17 to 24, which beam nothing;
#   moving:    the light carried along a path every frame, so that no history holds
#              and every frame is a first one.
# Prints a markdown table; each run's bench.md stays under OUT. The shared glTF
# close-ups (Sponza's arcades, Florence) run where ../shared/scenes is there.
#
#   sh scripts/soft-defaults-cost.sh [GNOMON] [OUT]
set -eu
gnomon=${1:-target/release/gnomon}
out=${2:-soft-defaults-cost}
mkdir -p "$out"
case "$gnomon" in /*) ;; *) gnomon="$(pwd)/$gnomon" ;; esac
bench() {
  dir=$1
  shift
  (cd "$out" && mkdir -p "$dir" && cd "$dir" &&
    "$gnomon" bench "$@" --techniques pcss --sweep refine=off,auto \
      --width 640 --height 360 > bench.log 2>&1) || { tail -5 "$out/$dir/bench.log" >&2; exit 1; }
}
# case name, the light path that moves it, then the scene and its flags.
run() {
  name=$1
  path=$2
  shift 2
  bench "$name/gathering" "$@" --warmup 0 --frames 16
  bench "$name/settled" "$@" --warmup 16 --frames 8
  # shellcheck disable=SC2086 # the path is two words, a flag and its value
  bench "$name/moving" "$@" $path --warmup 1 --frames 8
}
cases="spheres-spot contact-spot grazing-sun spheres-point"
run spheres-spot "--spot-path sweep" spheres --light spot --spot-radius 0.3
run contact-spot "--spot-path sweep" contact --light spot --spot-radius 0.5
run grazing-sun "--sun-path day" grazing --sun-angular-diameter 2
run spheres-point "--point-path sway" spheres --light point --point-radius 0.3
shared=$(cd "$(dirname "$0")/.." && pwd)/../shared/scenes
if [ -d "$shared" ]; then
  cases="$cases sponza-arcades florence"
  run sponza-arcades "--sun-path day" "$shared/sponza/sponza_geometry.glb" \
    --camera-eye 0,10,-4 --camera-target 60,20,-50 --fov 50 \
    --sun-elevation 70.17 --sun-azimuth 303.69 --sun-angular-diameter 2
  run florence "--sun-path day" "$shared/florence/florence.glb" \
    --camera-eye 250,150,350 --camera-target 0,0,0 --fov 50 \
    --sun-elevation 35 --sun-azimuth 40 --sun-angular-diameter 2
fi
python3 - "$out" $cases <<'PY'
import json, sys
out, cases = sys.argv[1], sys.argv[2:]
def frame(config):
    return next(p["median_ms"] for p in config["passes"] if p["name"] == "GPU frame")
print("| case | PCSS alone, ms | gathering: the defaults, ms (ratio) | settled | moving: the defaults, ms (ratio, beamed % of screen) |")
print("|---|---|---|---|---|")
for name in cases:
    cells = []
    pcss = None
    for run in ["gathering", "settled", "moving"]:
        configs = json.load(open(f"{out}/{name}/{run}/bench/bench.json"))["configs"]
        off, auto = (next(c for c in configs if c["sweep_value"] == v) for v in ("off", "auto"))
        pcss = frame(off) if run == "gathering" else pcss
        ratio = frame(auto) / frame(off)
        # A moving frame's beams are every frame's; a still view's last frame beams
        # what its gathering left, which says little.
        beamed = f", {auto['traced_percent']:.2f} %" if run == "moving" else ""
        cells.append(f"{frame(auto):.1f} (**{ratio:.2f}×**{beamed})")
    print(f"| {name} | {pcss:.1f} | " + " | ".join(cells) + " |")
PY
