#!/usr/bin/env python3
"""Lists WGSL names (fn, struct, alias, const, override, module-scope var) defined in
more than one .wgsl file of the crates: the definitions whose winner, when files are
concatenated, depends on which were composed. Usage:
wgsl-duplicates.py [ROOT] [--allow NAME,NAME...] (ROOT defaults to the repository).
Prints a count last; exits 1 when a name not allowed is defined twice. `.ci/run`
allows none: even the technique contract (`sample_shadow`, …) is implemented under
each module's name and bound by `techniques::technique_wgsl`. `--allow` is for
measuring an older checkout, where the contract was defined in every technique."""
import collections, pathlib, re, sys

args = sys.argv[1:]
allowed = set()
if "--allow" in args:
    i = args.index("--allow")
    allowed = set(args[i + 1].split(","))
    del args[i : i + 2]
root = pathlib.Path(args[0] if args else pathlib.Path(__file__).resolve().parent.parent)
# A definition may follow attributes (`@group(2) @binding(0) var shadow_map: …`,
# `@compute @workgroup_size(64) fn …`), on its line or on the lines above it.
definition = re.compile(
    r"^(?:@\w+(?:\([^)]*\))?\s*)*(?:fn|struct|alias|const|override|var(?:<[^>]*>)?)\s+([A-Za-z_][A-Za-z0-9_]*)",
    re.M,
)
where = collections.defaultdict(set)
for path in sorted(root.glob("crates/**/*.wgsl")):
    text = re.sub(r"//[^\n]*", "", path.read_text())
    for name in definition.findall(text):
        where[name].add(str(path.relative_to(root)))
duplicates = {n: sorted(f) for n, f in where.items() if len(f) > 1}
for name, files in sorted(duplicates.items()):
    print(f"{name}: {len(files)} files: {', '.join(files)}")
print(f"{len(duplicates)} names defined in more than one file")
refused = sorted(set(duplicates) - allowed)
if refused:
    print(f"not allowed: {', '.join(refused)}")
    sys.exit(1)
