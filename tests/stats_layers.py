#!/usr/bin/env python3
"""The statistics layer's own rules (issue 22, point 4; docs/architecture.md, "Layers").

1. No file of stats/ includes a solver header (a header found in solver/ but not in stats/ or
   solver/base/).
2. stats.c, stats.h, stats_nc.c, stats_nc.h and engine.h name no engine: no identifier that
   starts with an engine's prefix (euler_, corr_, lagr_, quad_); engines.c is the one list.
3. No circle among the object files of the library chansph_stats: an edge a -> b where a uses a
   symbol b defines (nm); the engines reach the layer only through what they call, never back.

usage: stats_layers.py LIBCHANSPH_STATS.a REPO_ROOT
Prints what it finds and exits 1 on any violation.
"""
import os
import re
import subprocess
import sys

ENGINE_PREFIXES = ("euler_", "corr_", "lagr_", "quad_")
GENERIC = ("stats.c", "stats.h", "stats_nc.c", "stats_nc.h", "engine.h")


def solver_includes(root):
    """Rule 1: the (file, header) pairs of stats/ that include a solver header."""
    stats, base = os.path.join(root, "stats"), os.path.join(root, "solver", "base")
    solver = set(os.listdir(os.path.join(root, "solver")))
    own = set(os.listdir(stats)) | set(os.listdir(base))
    bad = []
    for name in sorted(os.listdir(stats)):
        if not name.endswith((".c", ".h")):
            continue
        with open(os.path.join(stats, name)) as f:
            for inc in re.findall(r'^\s*#\s*include\s+"([^"]+)"', f.read(), re.M):
                if inc in solver and inc not in own:
                    bad.append((name, inc))
    return bad


def named_engines(root):
    """Rule 2: the (file, identifier) pairs of the generic files that name an engine."""
    bad = []
    for name in GENERIC:
        if not os.path.exists(os.path.join(root, "stats", name)):
            continue
        with open(os.path.join(root, "stats", name)) as f:
            text = re.sub(r"/\*.*?\*/|//[^\n]*", "", f.read(), flags=re.S)  # code, not comments
        text = re.sub(r'"(\\.|[^"\\])*"', '""', text)
        for ident in sorted(set(re.findall(r"\b[A-Za-z_]\w*", text))):
            if ident.startswith(ENGINE_PREFIXES):
                bad.append((name, ident))
    return bad


def symbol_graph(lib):
    """Rule 3: object -> the objects defining the symbols it uses."""
    out = subprocess.run(["nm", lib], capture_output=True, text=True, check=True).stdout
    defs, uses, obj = {}, {}, None
    for line in out.splitlines():
        if line.endswith(":"):
            obj = line[:-1].replace(".c.o", "")
            uses.setdefault(obj, set())
            continue
        parts = line.split()
        if len(parts) == 3 and parts[1] in "TDRBC":
            defs[parts[2]] = obj
        elif len(parts) == 2 and parts[0] == "U":
            uses[obj].add(parts[1])
    return {o: sorted({defs[s] for s in u if s in defs and defs[s] != o}) for o, u in uses.items()}


def circles(graph):
    """The circles a depth-first search meets (each as a list of objects)."""
    state, path, found = {}, [], []

    def visit(u):
        state[u] = 1
        path.append(u)
        for w in graph.get(u, ()):
            if state.get(w) == 1:
                found.append(path[path.index(w):] + [w])
            elif not state.get(w):
                visit(w)
        path.pop()
        state[u] = 2

    for u in sorted(graph):
        if not state.get(u):
            visit(u)
    return found


def main():
    lib, root = sys.argv[1], sys.argv[2]
    failures = 0
    for name, inc in solver_includes(root):
        print(f"stats/{name} includes the solver header {inc}")
        failures += 1
    for name, ident in named_engines(root):
        print(f"stats/{name} names an engine: {ident} (engines.c is the one list)")
        failures += 1
    graph = symbol_graph(lib)
    for c in circles(graph):
        print("circle among the statistics objects: " + " -> ".join(c))
        failures += 1
    print(f"{len(graph)} objects of chansph_stats, {sum(map(len, graph.values()))} edges: "
          + ("FAILED" if failures else "no solver header, no engine named, no circle"))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
