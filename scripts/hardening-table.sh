#!/bin/bash
# Issue 23's audit: bad or odd inputs of every kind through the release binary, each
# classified by what the user saw. Prints a markdown table per category and, with -v,
# one line per input.
#
#   bash scripts/hardening-table.sh [GNOMON] [SHARED_SCENES] [-v]
#
# Each input is run with a 60 s limit in a fresh directory. Outcomes:
#   clean error   exit 1 and a "gnomon: error:" line, nothing written
#   warned        exit 0 and a "gnomon: warning:" line (the input is odd, not wrong)
#   rendered      exit 0 for an input that is valid (the glTF corpus's good files)
#   panic         exit 101 or "panicked" anywhere in the output
#   hang          killed at 60 s
#   silent        exit 0 with neither warning nor error for an input that is nonsense
#   half-written  an error that left a file behind
set -u
gnomon=$(realpath "${1:-target/release/gnomon}")
shared=$(realpath "${2:-../shared/scenes}")
verbose=${3:-}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
small="--width 48 --height 32"

declare -A tried clean warned rendered panics hangs silent partial

# run CATEGORY EXPECT(error|warn|any) ARGS... ; in a fresh directory, with the files
# of $work/inputs copied in.
run() {
  local category=$1 expect=$2
  shift 2
  local dir="$work/run"
  rm -rf "$dir"
  mkdir -p "$dir"
  cp -r "$work/inputs/." "$dir/" 2>/dev/null
  local before
  before=$(cd "$dir" && find . -type f | sort)
  (cd "$dir" && timeout 60 env ${GNOMON_ENV:-} "$gnomon" "$@" > "$work/out" 2>&1)
  local rc=$?
  local after
  after=$(cd "$dir" && find . -type f | sort)
  local outcome
  if [ $rc -eq 124 ]; then outcome=hang
  elif [ $rc -eq 101 ] || grep -q "panicked" "$work/out"; then outcome=panic
  elif [ $rc -ne 0 ] && grep -q "gnomon: error:\|^error:" "$work/out"; then
    if [ "$before" != "$after" ]; then outcome=half-written; else outcome=clean; fi
  elif [ $rc -eq 0 ] && grep -q "gnomon: warning:" "$work/out"; then outcome=warned
  elif [ $rc -eq 0 ] && [ "$expect" = any ]; then outcome=rendered
  elif [ $rc -eq 0 ]; then outcome=silent
  else outcome="exit-$rc"
  fi
  tried[$category]=$(( ${tried[$category]:-0} + 1 ))
  case $outcome in
    clean) clean[$category]=$(( ${clean[$category]:-0} + 1 ));;
    warned) warned[$category]=$(( ${warned[$category]:-0} + 1 ));;
    rendered) rendered[$category]=$(( ${rendered[$category]:-0} + 1 ));;
    panic) panics[$category]=$(( ${panics[$category]:-0} + 1 ));;
    hang) hangs[$category]=$(( ${hangs[$category]:-0} + 1 ));;
    half-written) partial[$category]=$(( ${partial[$category]:-0} + 1 ));;
    *) silent[$category]=$(( ${silent[$category]:-0} + 1 ));;
  esac
  if [ -n "$verbose" ]; then
    echo "$category | $outcome | $* ${label:-} | $(grep -m1 "error:\|warning:" "$work/out" | cut -c1-160)" >&2
  fi
}

mkdir -p "$work/inputs"

# --- The glTF corpus: assimp's broken and odd files (valid ones must render). ---
while IFS= read -r file; do
  run "glTF corpus" any render "$file" $small --out o.png
done < <(find "$shared/assimp-gltf2" -name '*.gltf' -o -name '*.glb' | sort)

# --- Hand-made glTF: each case the audit named, written here, plus the inputs
# fuzzing found (crates/fuzz/regressions). Expected: a render, a warning or an error.
hand="$work/hand"
mkdir -p "$hand"
python3 - "$hand" <<'EOF'
import json, struct, sys, zlib
out = sys.argv[1]
quad = struct.pack('<12f', 0, 0, 0, 1, 0, 0, 0, 0, -1, 1, 0, -1) + struct.pack('<4H', 0, 1, 2, 3)
def glb(doc, binary):
    j = json.dumps(doc).encode()
    j += b' ' * (-len(j) % 4)
    binary += b'\0' * (-len(binary) % 4)
    body = struct.pack('<I4s', len(j), b'JSON') + j + struct.pack('<I4s', len(binary), b'BIN\0') + binary
    return b'glTF' + struct.pack('<II', 2, 12 + len(body)) + body
def doc(modes=(5,), count=4, matrix=None, extra=None, image_bytes=0):
    node = {"mesh": 0}
    if matrix: node["matrix"] = matrix
    d = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [node],
         "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": m} for m in modes]}],
         "buffers": [{"byteLength": 56 + image_bytes}],
         "bufferViews": [{"buffer": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 8}],
         "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, -1], "max": [1, 0, 0]},
                       {"bufferView": 1, "componentType": 5123, "count": count, "type": "SCALAR"}]}
    if image_bytes:
        d["bufferViews"].append({"buffer": 0, "byteOffset": 56, "byteLength": image_bytes})
        d["images"] = [{"bufferView": 2, "mimeType": "image/png"}]
    d.update(extra or {})
    return d
def chunk(kind, data):
    return struct.pack('>I', len(data)) + kind + data + struct.pack('>I', zlib.crc32(kind + data))
png = b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', 20000, 20000, 8, 6, 0, 0, 0)) + chunk(b'IDAT', b'') + chunk(b'IEND', b'')
cases = {
    "valid-strip.glb": doc((5,)),
    "valid-fan.glb": doc((6,)),
    "warn-lines-and-points.glb": doc((5, 1, 0)),
    "warn-zero-matrix.glb": doc(matrix=[0] * 16),
    "warn-texture-transform.glb": doc(extra={"extensionsUsed": ["KHR_texture_transform"]}),
    "error-points-only.glb": doc((0,)),
    "error-index-overrun.glb": doc((4,), count=600),
    "error-required-quantization.glb": doc(extra={"extensionsUsed": ["KHR_mesh_quantization"], "extensionsRequired": ["KHR_mesh_quantization"]}),
}
for name, d in cases.items():
    open(f"{out}/{name}", "wb").write(glb(d, quad))
open(f"{out}/error-png-20000-squared.glb", "wb").write(glb(doc(image_bytes=len(png)), quad + png))
EOF
for file in "$hand"/*.glb "$(dirname "$0")"/../crates/fuzz/regressions/gltf/*; do
  case $(basename "$file") in
    valid-*) expect=any;;
    warn-*) expect=warn;;
    *) expect=error;;
  esac
  run "hand-made glTF" "$expect" render "$(realpath "$file")" $small --out o.png
done

# --- Scene files: every light, view and model value out of range, and typos. ---
scene_file() {
  printf 'builtin = "columns"\n%b' "$1" > "$work/inputs/s.toml"
  label="[$(printf '%b' "$1" | tr '\n' ' ')]" run "scene files" error render s.toml $small --out o.png
}
for t in \
  '[spot]\nposition = [2, 6, 1]\ntarget = [0, 0, 0]\nouter_angle = 40\ninner_angle = -50\nrange = 30\n' \
  '[spot]\nposition = [2, 6, 1]\ntarget = [0, 0, 0]\nouter_angle = 95\nrange = 30\n' \
  '[spot]\nposition = [2, 6, 1]\ntarget = [2, 6, 1]\nouter_angle = 40\nrange = 30\n' \
  '[spot]\nposition = [2, 6, 1]\ntarget = [0, 0, 0]\nouter_angle = 40\nrange = 0\n' \
  '[spot]\nposition = [2, nan, 1]\ntarget = [0, 0, 0]\nouter_angle = 40\nrange = 30\n' \
  '[spot]\nposition = [2, 6, 1]\ntarget = [0, 0, 0]\nouter_angle = 40\nrange = 30\nradius = -1\n' \
  '[sun]\nelevation = 40\nazimuth = 10\ncolor = [nan, -1, 1e38]\n' \
  '[sun]\nelevation = nan\nazimuth = 10\n' \
  '[sun]\nelevation = -30\nazimuth = 10\n' \
  '[sun]\nelevation = 0\nazimuth = 10\n' \
  '[sun]\nelevation = 30\nazimuth = inf\n' \
  '[sun]\nelevation = 30\nazimuth = 10\nangular_diameter = 1e30\n' \
  '[sun]\nelevation = 30\nazimuth = 10\nintensity = -2\n' \
  '[point]\nposition = [0, 2, 0]\nrange = -1\n' \
  '[point]\nposition = [0, 2, 0]\nrange = 5\nradius = inf\n' \
  '[[light]]\ntype = "point"\nposition = [0, 2, 0]\nrange = 5\nintensity = nan\n' \
  '[[light]]\ntype = "area"\n' \
  '[[light]]\ntype = "sun"\nelevation = 40\n' \
  '[[light]]\ntype = "point"\nposition = [0, 2, 0]\nrange = 5\ncolor = [1, 1]\n' \
  '[[light]]\ntype = "point"\nposition = [0, 2, 0]\nrange = 5\n[light.shadow]\nmap.resolution = 3\n' \
  '[[view]]\nname = "a"\neye = [0, 3, 9]\ntarget = [0, 1, 0]\nfov = 0\n' \
  '[[view]]\nname = "a"\neye = [0, 3, 9]\ntarget = [0, 1, 0]\nfov = 180\n' \
  '[[view]]\nname = "a"\neye = [0, 3, 9]\ntarget = [0, 1, 0]\nnear = -1\n' \
  '[[view]]\nname = "a"\neye = [0, 3, 9]\ntarget = [0, 1, 0]\nnear = 5\nfar = 1\n' \
  '[[view]]\nname = "a"\neye = [0, 3, 9]\ntarget = [0, 3, 9]\n' \
  '[settings.shadow.map]\nresolution = 3\n' \
  '[settings.shadow.bias]\nslope_bias = 1e30\n' \
  '[settings.shadow.bias]\ndepth_bias = 2147483647\n' \
  '[settings.shadow.filter]\ntechnique = "No pe"\n' \
  '[settings.shadow.map]\nresolutoin = 512\n' \
  '[settings.image]\nwidth = 0\n' \
  '[settings.light]\nsun_elevation = -5\n' \
  'ground = "yes"\n' \
  '[[model]]\nfile = "missing.glb"\n' \
  'builtin = "nowhere"\n' \
  '[unclosed\n' \
  ; do scene_file "$t"; done
printf 'builtin = "columns"\n[settings.light]\nlight_index = 3\n' > "$work/inputs/s.toml"
run "scene files" warn render s.toml $small --out o.png
rm -f "$work/inputs/s.toml"

# --- Flags: every number beyond its range, and settings with no effect. ---
for f in "--depth-bias 2147483647" "--depth-bias -2147483647" "--slope-bias 1e30" "--slope-bias -1" \
  "--normal-offset 1e9" "--normal-offset nan" "--sun-elevation 0" "--sun-elevation -30" "--sun-elevation nan" \
  "--sun-azimuth inf" "--sun-angular-diameter 1e30" "--fov 0" "--fov 180" "--camera-near -1" \
  "--camera-near 5 --camera-far 1" "--camera-eye 1,2" "--camera-eye 1,2,nan" "--spot-outer-angle 95" \
  "--spot-inner-angle -50" "--spot-range 0" "--point-radius -1" "--shadow-res 3" "--shadow-res 99999" \
  "--pcf-kernel 0" "--cascades 0" "--cascades 99" "--samples 1" "--width 0" "--height 70000" \
  "--technique nope" "--light moon" "--refine rays --shadow-path forward" "--light all" "instances:5000000" \
  "instances:many" "no-such-scene" "--out o.txt" "--out missing/o.png" "--visibility-out v.txt" \
  "--csm-scale 1e30" "--contact-distance 1e30" "--contact-bias inf" "--kernel-unit world --pcf-kernel 1e30"; do
  # shellcheck disable=SC2086
  run flags error render $small $f
done
for f in "--light-index 2" "--omni paraboloid" "--spot-range 4" "--cascade-blend 0.2" "--sun-elevation 40 --light spot"; do
  # shellcheck disable=SC2086
  run flags warn render $small $f
done

# --- Adapters: no Vulkan driver, OpenGL forced, no backend at all. ---
GNOMON_ENV="-u WGPU_BACKEND VK_ICD_FILENAMES=/nonexistent" run adapters any render $small
GNOMON_ENV="WGPU_BACKEND=gl" run adapters error render $small
GNOMON_ENV="WGPU_BACKEND=" run adapters error render $small
GNOMON_ENV="-u XDG_RUNTIME_DIR" run adapters any render $small

# --- Outputs: destinations that collide, and impossible ones. ---
mkdir -p "$work/inputs/D"
run outputs error render $small --out same.png --shadow-map-out ./same.png
run outputs error render $small --aov-out D --visibility-out D/visibility.exr --out a.png
run outputs error compare $small --techniques pcf,pcf --out cmp
run outputs error render $small --out D
run outputs error render $small --aov-out o.png/x
run outputs error reference $small --out r.exr --std-error-out r.exr
rm -rf "$work/inputs/D"

echo "| inputs | tried | clean errors | warned | rendered (valid input) | panics | hangs | silently accepted | half-written |"
echo "|---|---|---|---|---|---|---|---|---|"
for c in "glTF corpus" "hand-made glTF" "scene files" flags adapters outputs; do
  echo "| $c | ${tried[$c]:-0} | ${clean[$c]:-0} | ${warned[$c]:-0} | ${rendered[$c]:-0} | ${panics[$c]:-0} | ${hangs[$c]:-0} | ${silent[$c]:-0} | ${partial[$c]:-0} |"
done
