#!/usr/bin/env python3
"""The module graph of the library: which module of src/ uses which (any `crate::` path,
tests excluded), its import cycles, the imports that run up the layer order, and the
longest files and functions.

The layers are the folders of src/, in the order `src/lib.rs` declares them (bottom
first); a module is a file of a layer (`model::contact`), or a folder in one with all its
files (`io::checkpoint`), or the layer's own `mod.rs` where it holds code (`engine`,
`neighbours`, `scenario`). Flat files of src/ (the layout before the layers) count as
modules of a layer of their own, "flat".

    python3 bench/modgraph.py            # from the repository root
    python3 bench/modgraph.py --check    # exit 1 on a cycle or an import up the layers
    python3 bench/modgraph.py --edges    # also print every module's imports
"""
import os
import re
import sys

src = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
lib = open(os.path.join(src, "lib.rs")).read()
layers = re.findall(r"^pub mod (\w+);", lib, re.M)
rank = {name: i for i, name in enumerate(layers)}


def module_of(parts):
    """The module a path below src/ (its components, without `.rs`) belongs to."""
    if parts[0] not in rank:
        return parts[0]
    if len(parts) == 1 or parts[1] == "mod":
        return parts[0]
    return parts[0] + "::" + parts[1]


def layer_of(module):
    return module.split("::")[0] if module.split("::")[0] in rank else "flat"


files = {}
for root, _, names in os.walk(src):
    for f in names:
        if f.endswith(".rs"):
            rel = os.path.relpath(os.path.join(root, f), src)
            parts = rel.removesuffix(".rs").split(os.sep)
            code = open(os.path.join(root, f)).read()
            only_mods = all(
                not l.strip() or l.lstrip().startswith("//") or re.match(r"pub mod \w+;$", l.strip())
                for l in code.splitlines()
            )
            if parts[0] not in ("main", "lib", "bin") and not only_mods:
                files[rel] = module_of(parts)
modules = set(files.values())


def target(path):
    """The module a `crate::a::b::...` path names."""
    parts = path.split("::")
    for n in (2, 1):
        if len(parts) >= n:
            m = module_of(parts[:n]) if parts[0] in rank else parts[0]
            if m in modules:
                return m
    return None


uses, sizes, functions = {m: set() for m in modules}, [], []
for rel, mod in files.items():
    text = open(os.path.join(src, rel)).read()
    body = text.split("#[cfg(test)]")[0]
    sizes.append((len(text.splitlines()), rel))
    for m in re.finditer(r"crate::((?:\w+::)*\w+)", body):
        t = target(m[1])
        if t and t != mod:
            uses[mod].add(t)
    # Functions: from a `fn` line to the line closing it at the same indentation.
    lines = body.splitlines()
    for i, line in enumerate(lines):
        m = re.match(r"(\s*)(pub(\([^)]*\))? )?(const )?(unsafe )?fn (\w+)", line)
        if not m or line.rstrip().endswith(";"):
            continue
        indent = m[1]
        for j in range(i + 1, len(lines)):
            if lines[j].startswith(indent + "}") and not lines[j].startswith(indent + "} else"):
                functions.append((j - i + 1, f"{rel}: {m[6]}"))
                break
mods = sorted(modules)

# Strongly connected components (Tarjan).
index, low, stack, on, comps, counter = {}, {}, [], set(), [], [0]


def visit(v):
    index[v] = low[v] = counter[0]
    counter[0] += 1
    stack.append(v)
    on.add(v)
    for w in sorted(uses[v]):
        if w not in index:
            visit(w)
            low[v] = min(low[v], low[w])
        elif w in on:
            low[v] = min(low[v], index[w])
    if low[v] == index[v]:
        comp = []
        while True:
            w = stack.pop()
            on.discard(w)
            comp.append(w)
            if w == v:
                break
        comps.append(sorted(comp))


sys.setrecursionlimit(10000)
for v in mods:
    if v not in index:
        visit(v)
cycles = [c for c in comps if len(c) > 1]
up = [
    (a, b)
    for a in mods
    for b in sorted(uses[a])
    if layer_of(a) != "flat" and layer_of(b) != "flat" and rank[layer_of(b)] > rank[layer_of(a)]
]
edges = sum(len(d) for d in uses.values())
print(f"{len(mods)} modules in {len(layers)} layers ({' < '.join(layers)}), {edges} imports between them")
if "--edges" in sys.argv:
    for m in mods:
        print(f"  {m} -> {' '.join(sorted(uses[m]))}")
print(f"modules in import cycles: {len(cycles)} group(s)")
for c in cycles:
    inner = [(a, b) for a in c for b in sorted(uses[a]) if b in c]
    print("  " + ", ".join(c) + ": " + "; ".join(f"{a} -> {b}" for a, b in inner))
print(f"imports up the layers: {len(up)}" + "".join(f"\n  {a} -> {b}" for a, b in up))
print("longest files:", ", ".join(f"{r} {n}" for n, r in sorted(sizes, reverse=True)[:6]))
long = sorted(functions, reverse=True)
print(f"functions over 80 lines: {sum(1 for n, _ in long if n > 80)}; longest:",
      ", ".join(f"{r} {n}" for n, r in long[:6]))
if "--check" in sys.argv and (cycles or up):
    sys.exit(1)
