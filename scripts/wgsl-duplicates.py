#!/usr/bin/env python3
"""Lists WGSL names (fn, struct, alias, const, override, module-scope var) defined in
more than one .wgsl file of the crates: the definitions whose winner, when files are
concatenated, depends on which were composed. Usage: wgsl-duplicates.py [ROOT]
(default: the repository). Exits 0; prints a count last."""
import collections, pathlib, re, sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
definition = re.compile(r"^(?:fn|struct|alias|const|override|var(?:<[^>]*>)?)\s+([A-Za-z_][A-Za-z0-9_]*)", re.M)
where = collections.defaultdict(set)
for path in sorted(root.glob("crates/**/*.wgsl")):
    text = re.sub(r"//[^\n]*", "", path.read_text())
    for name in definition.findall(text):
        where[name].add(str(path.relative_to(root)))
duplicates = {n: sorted(f) for n, f in where.items() if len(f) > 1}
for name, files in sorted(duplicates.items()):
    print(f"{name}: {len(files)} files: {', '.join(files)}")
print(f"{len(duplicates)} names defined in more than one file")
