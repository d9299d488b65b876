#!/usr/bin/env sh
# Renders the same settings with two `gnomon` binaries and compares the PNGs pixel
# by pixel: the check behind "no behaviour change" for a refactor. Most settings
# turn refinement by rays off, so that each technique's own answer shows. Usage:
#   sh scripts/same-images.sh OLD_GNOMON NEW_GNOMON [WORKDIR]
# Build the old one from a worktree (`git worktree add /tmp/old REV`). Sharing this
# checkout's target directory saves the dependencies' build, but cargo keys a
# workspace member's artifacts by its path inside the workspace and trusts them
# while its files look older than the last build: touch every source of the
# checkout being built first (`find crates examples -type f -exec touch {} +`),
# then `CARGO_TARGET_DIR=/path/to/target cargo build -p gnomon`, and copy the
# binary aside before building the other. Check that the two binaries differ
# (`cmp`). Needs python3 with numpy and Pillow. Exits 1 if any image differs or
# fails to render.
set -eu
old=$1
new=$2
dir=${3:-$(mktemp -d)}
mkdir -p "$dir"
if cmp -s "$old" "$new"; then
  echo "$old and $new are the same binary: nothing would be compared"
  exit 1
fi
i=0
status=0
while IFS= read -r args; do
  [ -z "$args" ] && continue
  i=$((i + 1))
  # shellcheck disable=SC2086
  "$old" render $args --width 320 --height 240 --out "$dir/old_$i.png" >/dev/null 2>"$dir/old_$i.err" || { echo "$i: the old binary failed: $args"; status=1; }
  # shellcheck disable=SC2086
  "$new" render $args --width 320 --height 240 --out "$dir/new_$i.png" >/dev/null 2>"$dir/new_$i.err" || { echo "$i: the new binary failed: $args"; status=1; }
  echo "$i: $args" >>"$dir/list.txt"
done <<'LIST'
spheres
spheres --refine off
spheres --refine off --technique vsm
spheres --refine off --technique evsm4
spheres --refine off --technique msm-hausdorff
spheres --refine off --technique esm
spheres --refine off --technique convolution
spheres --refine off --technique msm-hamburger --moment-format rgba16float
spheres --refine off --light spot --technique pcss --spot-radius 0.3
spheres --refine off --light point --technique pcf-poisson
spheres --refine off --light point --omni paraboloid --technique hard
spheres --light spot --technique pcf --pcf-kernel 5 --shadow-path mask --contact-shadows
lamps --light all --shadow-path mask
columns --refine off --partition cascades --cascades 4 --sdsm
spheres --light spot --spot-radius 0.2 --refine rays --shadow-path mask
spheres --technique raytraced
spheres --refine off --partition cascades --cascades 3 --receiver-plane-bias true --technique pcf-tent
spheres --refine off --technique pcss --sun-angular-diameter 3
spheres --sun-angular-diameter 2 --refine rays --shadow-path mask
spheres --light point --point-radius 0.2 --refine rays --shadow-path mask
spheres --light point --point-radius 0.2 --refine rays --contact-shadows
lamps --light spot --refine off
lamps:4 --light sun --refine off
lamps:4 --light point --refine off
LIST
python3 - "$dir" "$i" <<'PY' || status=1
import sys
import numpy as np
from PIL import Image
folder, count = sys.argv[1], int(sys.argv[2])
names = open(f"{folder}/list.txt").read().splitlines()
differ = 0
for k in range(1, count + 1):
    a = np.asarray(Image.open(f"{folder}/old_{k}.png")).astype(int)
    b = np.asarray(Image.open(f"{folder}/new_{k}.png")).astype(int)
    d = np.abs(a - b).max(axis=-1)
    n = int(np.count_nonzero(d))
    differ += n > 0
    print(f"{names[k - 1]}: {'identical' if n == 0 else f'{n} pixels differ, by up to {d.max()}'}")
print(f"{count - differ} of {count} images identical")
# Settings whose images coincide test less than they seem (refinement by rays makes
# every technique's edges the rays' answer): say how many differ from one another.
import hashlib
distinct = len({hashlib.sha256(open(f"{folder}/new_{k}.png", "rb").read()).digest() for k in range(1, count + 1)})
print(f"{distinct} of {count} images distinct from one another")
sys.exit(1 if differ else 0)
PY
exit $status
