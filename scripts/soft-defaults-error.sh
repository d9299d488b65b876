#!/bin/sh
# Issue 74's error tables, from `gnomon compare --motion`: the penumbra MAE at the
# defaults (only the light's size given; the default technique) against Monte Carlo
# references, frame by frame.
#
# - A still view, 480×270 against a 4096-ray reference: frames 1, 4 and 16 (the
#   penumbra history gathers a beam of every unsure pixel each four frames).
# - A moving light or caster, 320×180, each frame against its own 1024-ray
#   reference: every frame is the first after a cut (the history is thrown away),
#   and the table gives the worst and the mean over 16 frames.
#
# Each run's metrics.md, motion.png and motion-error.png stay under OUT.
#
#   sh scripts/soft-defaults-error.sh [GNOMON] [OUT]
set -eu
gnomon=${1:-target/release/gnomon}
out=${2:-soft-defaults-error}
mkdir -p "$out"
run() {
  name=$1
  shift
  "$gnomon" compare "$@" --techniques pcf2x2 --path-frames 16 -o "$out/$name" > "$out/$name.log" 2>&1 ||
    { tail -5 "$out/$name.log" >&2; exit 1; }
}
still="--motion still --width 480 --height 270 --samples 4096"
moving="--width 320 --height 180 --samples 1024"
run still-spheres-spot spheres --light spot --spot-radius 0.3 $still
run still-contact-spot contact --light spot --spot-radius 0.5 $still
run still-grazing-sun grazing --sun-angular-diameter 2 $still
run still-spheres-point spheres --light point --point-radius 0.3 $still
run casters-contact-spot contact --light spot --spot-radius 0.5 --motion casters $moving
run sweep-contact-spot contact --light spot --spot-radius 0.5 --motion spot-sweep $moving
run day-grazing-sun grazing --sun-angular-diameter 2 --motion sun-day $moving
run sway-spheres-point spheres --light point --point-radius 0.3 --motion point-sway $moving
python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
def frames(name):
    motion = json.load(open(f"{out}/{name}/metrics.json"))["motion"][0]["frames"]
    return [f["penumbra_mae"] for f in motion]
print("| still view, 480×270, 4096-ray reference | frame 1 | frame 4 | frame 16 |")
print("|---|---|---|---|")
for name in ["still-spheres-spot", "still-contact-spot", "still-grazing-sun", "still-spheres-point"]:
    e = frames(name)
    print(f"| {name[6:]} | {e[0]:.4f} | {e[3]:.4f} | **{e[15]:.4f}** |")
print()
print("| moving, 320×180, 1024-ray reference per frame | worst frame | mean of 16 |")
print("|---|---|---|")
for name in ["casters-contact-spot", "sweep-contact-spot", "day-grazing-sun", "sway-spheres-point"]:
    e = frames(name)
    print(f"| {name} | **{max(e):.4f}** | {sum(e) / len(e):.4f} |")
PY
