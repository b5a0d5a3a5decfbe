#!/usr/bin/python3
"""Table and plot of the Taylor-Green check (thesis Sec. 6.2.2) for docs/validation/taylor_green.md.

Usage: tests/taylor_green_doc.py BUILD/tests/taylor_green DOCDIR
Runs the check on the regular lattice and with a 0.2 dr jitter, writes DOCDIR/taylor_green.png
and prints the markdown tables.
"""
import subprocess
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def table(exe, jitter):
    out = subprocess.run([exe, "--jitter", str(jitter)], capture_output=True, text=True,
                         check=True).stdout
    return np.array([[float(v) for v in l.split()] for l in out.splitlines() if l[0] != "#"])


def first_below(t, col, lim=0.1):
    for row in t:
        if row[col] <= lim:
            return "%d" % row[0]
    return "> %d" % t[-1, 0]


def main():
    exe, doc = sys.argv[1], sys.argv[2]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, jit in zip(axes, (0.0, 0.2)):
        t = table(exe, jit)
        print("\n### %s\n" % ("regular lattice" if jit == 0 else "lattice jittered by up to 0.2 dr"))
        print("| particles per vortex | particles | L2 standard | Linf standard | L2 corrected | "
              "Linf corrected | time standard [ms] | time corrected [ms] |")
        print("|---|---|---|---|---|---|---|---|")
        for r in t:
            print("| %d | %d | %.3e | %.3e | %.3e | %.3e | %.3f | %.3f |"
                  % (r[0], r[1], r[2], r[3], r[4], r[5], 1e3 * r[6], 1e3 * r[7]))
        print("\nParticles per vortex for 10%% error: standard L2 %s, Linf %s; corrected L2 %s, "
              "Linf %s (thesis, standard: 18 and 21).\n"
              % (first_below(t, 2), first_below(t, 3), first_below(t, 4), first_below(t, 5)))
        for col, lab, st in ((2, "standard L2", "o-"), (3, "standard Linf", "o--"),
                             (4, "corrected L2", "s-"), (5, "corrected Linf", "s--")):
            ax.loglog(t[:, 0], t[:, col], st, label=lab)
        ax.axhline(0.1, color="gray", lw=0.8)
        ax.set_xlabel("particles per vortex 1/(2 dr)")
        ax.set_ylabel("relative error of Pi_xx")
        ax.set_title("regular lattice" if jit == 0 else "jittered lattice (0.2 dr)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(doc + "/taylor_green.png", dpi=110)


if __name__ == "__main__":
    main()
