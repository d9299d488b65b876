#!/usr/bin/env python3
"""Lists the import circles of a crate: the strongly connected components, larger than
one file, of its files' `crate::`, `super::` and `self::` references (a `use` or a
path in code; comments and strings blanked). A parent's `mod child;` is its
own structure, not an import, and by default neither are its unprefixed `child::` paths.
`--edges` lists each circle's references; `--gate` exits 1 when a circle holds more
than two files (issue 50: none larger than a pair). `--children` counts a parent's
unprefixed `child::` paths too, as issue 77 asks (a parent that calls its child
depends on it): not yet gated, since the render crate's passes and frame modules
still form circles so counted (docs/architecture.md). Usage: import-circles.py
[CRATE_SRC] (default crates/render/src). Prints each circle's files and a count
last."""
import pathlib, re, sys

CHILD = '--children' in sys.argv
args = [a for a in sys.argv[1:] if not a.startswith("--")]
src = pathlib.Path(args[0] if args else "crates/render/src")
files = sorted(p for p in src.rglob("*.rs"))


def module_of(path):
    parts = list(path.relative_to(src).with_suffix("").parts)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return tuple(parts)


modules = {module_of(p): p for p in files}


def blank(text):
    """Comments and string literals emptied, in one pass (a string may hold `//`)."""
    token = re.compile(r'//[^\n]*|r#*"[^"]*"#*|"(?:\\.|[^"\\])*"|\'(?:\\.|[^\'\\])\'')
    return token.sub(lambda m: "" if m.group(0).startswith("//") else '""', text)


def resolve(path):
    """The longest module prefix of `path` that is a file of the crate."""
    for n in range(len(path), -1, -1):
        if tuple(path[:n]) in modules:
            return tuple(path[:n])
    return None


def targets(module, path, text):
    found = set()
    is_mod_file = path.stem in ("mod", "lib", "main")
    # `use` trees with braces: expand one level of `a::{b, c::d}`.
    for m in re.finditer(r"\b(crate|super|self)((?:::\w+)*)::\{([^{}]*(?:\{[^{}]*\}[^{}]*)*)\}", text):
        base = m.group(2).split("::")[1:]
        for item in re.split(r",(?![^{]*\})", m.group(3)):
            item = item.strip().split("::{")[0]
            if item:
                found.add((m.group(1), tuple(base + item.split("::"))))
    for m in re.finditer(r"\b(crate|super|self)((?:::\w+)+)", text):
        found.add((m.group(1), tuple(m.group(2).split("::")[1:])))
    if CHILD:
        for m in re.finditer(r"(?<![:\w])(\w+)((?:::\w+)+)", text):
            head = m.group(1)
            child = module + (head,) if is_mod_file else None
            if child is not None and child in modules:
                found.add(("self", tuple([head] + m.group(2).split("::")[1:])))
    out = set()
    for root, rest in found:
        rest = [r for r in rest if r not in ("self", "*")]
        if root == "crate":
            start = ()
        elif root == "self":
            start = module
        else:
            start = module[:-1]
            while rest and rest[0] == "super":
                start, rest = start[:-1], rest[1:]
        target = resolve(list(start) + list(rest))
        if target is not None and target != module:
            out.add(target)
    return out


graph = {m: targets(m, p, blank(p.read_text())) for m, p in modules.items()}

# Tarjan's strongly connected components.
index, low, stack, on, sccs, counter = {}, {}, [], set(), [], [0]
sys.setrecursionlimit(10000)


def visit(v):
    index[v] = low[v] = counter[0]
    counter[0] += 1
    stack.append(v)
    on.add(v)
    for w in graph[v]:
        if w not in index:
            visit(w)
            low[v] = min(low[v], low[w])
        elif w in on:
            low[v] = min(low[v], index[w])
    if low[v] == index[v]:
        scc = []
        while True:
            w = stack.pop()
            on.discard(w)
            scc.append(w)
            if w == v:
                break
        sccs.append(scc)


for v in graph:
    if v not in index:
        visit(v)
circles = sorted((sorted("::".join(m) or "lib" for m in s) for s in sccs if len(s) > 1), key=len, reverse=True)
for c in circles:
    print(f"{len(c)} files: {', '.join(c)}")
print(f"{len(circles)} import circles; {sum(len(c) > 2 for c in circles)} larger than a pair; largest {max((len(c) for c in circles), default=0)} files")

if "--edges" in sys.argv:
    for c in sccs:
        if len(c) > 1:
            for v in c:
                for w in sorted(graph[v]):
                    if w in c:
                        print(f"  {'::'.join(v) or 'lib'} -> {'::'.join(w) or 'lib'}")

if "--gate" in sys.argv and any(len(c) > 2 for c in circles):
    sys.exit(1)
