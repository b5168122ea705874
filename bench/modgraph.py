#!/usr/bin/env python3
"""The module graph of the library: which top-level module of src/ uses which (any
`crate::NAME` path, tests excluded), its import cycles, and the longest files and functions.

    python3 bench/modgraph.py            # from the repository root
"""
import os
import re
import sys

src = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
uses = {}
sizes = []
functions = []
for root, _, files in os.walk(src):
    for f in files:
        if not f.endswith(".rs"):
            continue
        path = os.path.join(root, f)
        rel = os.path.relpath(path, src)
        top = rel.split(os.sep)[0].removesuffix(".rs")
        if top in ("main", "lib"):
            continue
        text = open(path).read()
        body = text.split("#[cfg(test)]")[0]
        sizes.append((len(text.splitlines()), rel))
        deps = uses.setdefault(top, set())
        for m in re.finditer(r"crate::(\w+)", body):
            if m[1] != top:
                deps.add(m[1])
        for m in re.finditer(r"use crate::\{([^}]*)\}", body):
            for name in re.findall(r"(?:^|,)\s*(\w+)", m[1]):
                if name != top:
                    deps.add(name)
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
mods = sorted(uses)
for m in mods:
    uses[m] &= set(mods)

# Strongly connected components (Tarjan).
index, low, stack, on, comps, counter = {}, {}, [], set(), [], [0]
def visit(v):
    index[v] = low[v] = counter[0]; counter[0] += 1
    stack.append(v); on.add(v)
    for w in sorted(uses[v]):
        if w not in index:
            visit(w); low[v] = min(low[v], low[w])
        elif w in on:
            low[v] = min(low[v], index[w])
    if low[v] == index[v]:
        comp = []
        while True:
            w = stack.pop(); on.discard(w); comp.append(w)
            if w == v:
                break
        comps.append(sorted(comp))
sys.setrecursionlimit(10000)
for v in mods:
    if v not in index:
        visit(v)
cycles = [c for c in comps if len(c) > 1]
edges = sum(len(d) for d in uses.values())
print(f"{len(mods)} modules, {edges} imports between them")
print(f"modules in import cycles: {len(cycles)} group(s)")
for c in cycles:
    inner = [(a, b) for a in c for b in sorted(uses[a]) if b in c]
    print("  " + ", ".join(c) + ": " + "; ".join(f"{a} -> {b}" for a, b in inner))
print("longest files:", ", ".join(f"{r} {n}" for n, r in sorted(sizes, reverse=True)[:6]))
long = sorted(functions, reverse=True)
print(f"functions over 80 lines: {sum(1 for n, _ in long if n > 80)}; longest:",
      ", ".join(f"{r} {n}" for n, r in long[:6]))
