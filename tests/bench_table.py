#!/usr/bin/python3
"""Medians of `chansph bench` runs, per build and ranks x threads, from a log of runs.

usage: tests/bench_table.py LOG [--csv OUT.csv]

LOG holds runs, each after a line "=== build=B ranks=R threads=T rep=K ..." (tests/bench_scaling.sh
and docs/perf/node16.sh write it). Prints per build and layout: runs, ms/step, particle-steps/s,
efficiency against 1 x 1 of the same build, and the per-phase seconds per step of rank 0 (the
sort: "sort" + "sort:permute"; the halo: every "halo*" phase, of which "halo:wait" is the time
in MPI waits), each a median over the runs. --csv writes one row per run.

Then, per build, the serial fractions on two cores: the sort's from 1 x 1 and 1 x 2 (Amdahl: a
phase of time T1 on one thread and T2 on two has the serial fraction f = 2 T2 / T1 - 1 of its
time; f T1 / step(1 x 1) of the one-thread step), and the halo's on 2 x 1 (work the one-rank
run does not do at all: its own work, without the MPI waits, and with them, over the step).
"""
import re
import statistics
import sys


def parse(path):
    runs, cur = [], None
    for line in open(path, errors="replace"):
        m = re.match(r"=== build=(\S+) ranks=(\d+) threads=(\d+) rep=(\d+)", line)
        if m:
            cur = {"build": m[1], "ranks": int(m[2]), "threads": int(m[3]), "rep": int(m[4]),
                   "phases": {}}
            runs.append(cur)
            continue
        if cur is None:
            continue
        m = re.search(r"then (\d+) timed steps in ([0-9.]+) s \(([0-9.]+) ms/step\)", line)
        if m:
            cur["steps"], cur["ms"] = int(m[1]), float(m[3])
        m = re.match(r"particle-steps/s: ([0-9.]+)", line)
        if m:
            cur["psps"] = float(m[1])
        m = re.match(r"halo exchange and migration per step: ([0-9.]+) ms max", line)
        if m:
            cur["halo_max_ms"] = float(m[1])
        m = re.search(r"; ([0-9.]+) kB and ([0-9.]+) messages sent per rank", line)
        if m:
            cur["kB"] = float(m[1])
        m = re.match(r"(\S+)\s+([0-9.]+)\s+[0-9.]+%\s*(\d*)$", line.strip())
        if m and not line.startswith("  "):
            cur["phases"][m[1]] = float(m[2])
    return [r for r in runs if "ms" in r and "psps" in r]


def groups(runs):
    out = {}
    for r in runs:
        out.setdefault((r["build"], r["ranks"], r["threads"]), []).append(r)
    return out


def med(xs):
    return statistics.median(xs) if xs else float("nan")


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    runs = parse(sys.argv[1])
    if "--csv" in sys.argv:
        names = sorted({p for r in runs for p in r["phases"]})
        with open(sys.argv[sys.argv.index("--csv") + 1], "w") as f:
            f.write("build,ranks,threads,rep,steps,ms_per_step,particle_steps_per_s,halo_max_ms,"
                    "kB_per_rank_step," + ",".join("s_" + n for n in names) + "\n")
            for r in runs:
                f.write(",".join(str(x) for x in [r["build"], r["ranks"], r["threads"], r["rep"],
                                                   r["steps"], r["ms"], r["psps"],
                                                   r.get("halo_max_ms", 0), r.get("kB", 0)]
                                 + [r["phases"].get(n, 0.0) for n in names]) + "\n")
    g = groups(runs)
    print("| build | ranks x threads | runs | ms/step | particle-steps/s | efficiency | "
          "sort ms/step | halo ms/step (of which MPI wait) | neighbours | forces | other phases |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for key in sorted(g, key=lambda k: (k[0], k[1] * k[2], -k[1])):
        rs = g[key]
        base = g.get((key[0], 1, 1))
        ps = med([r["psps"] for r in rs])
        eff = ps / (key[1] * key[2] * med([r["psps"] for r in base])) if base else float("nan")

        def ph(sel):
            return med([sum(v for n, v in r["phases"].items() if sel(n)) * 1e3 / r["steps"]
                        for r in rs])
        sort = ph(lambda n: n.startswith("sort"))
        halo = ph(lambda n: n.startswith("halo"))
        wait = ph(lambda n: n == "halo:wait")
        nb, fo = ph(lambda n: n == "neighbours"), ph(lambda n: n == "forces")
        rest = med([r["ms"] for r in rs]) - sort - halo - nb - fo
        print(f"| {key[0]} | {key[1]} x {key[2]} | {len(rs)} | {med([r['ms'] for r in rs]):.1f} | "
              f"{ps / 1e6:.3f} M | {100 * eff:.0f}% | {sort:.1f} | {halo:.1f} ({wait:.1f}) | "
              f"{nb:.1f} | {fo:.1f} | {rest:.1f} |")
    serial_fractions(g)


def serial_fractions(g):
    """The sort's and the halo's serial fractions on two cores, per build (see the doc)."""
    rows = []
    for b in sorted({k[0] for k in g}):
        one, two, ranks = g.get((b, 1, 1)), g.get((b, 1, 2)), g.get((b, 2, 1))
        if not one:
            continue

        def ph(rs, sel):
            return med([sum(v for n, v in r["phases"].items() if sel(n)) * 1e3 / r["steps"]
                        for r in rs])
        step1 = med([r["ms"] for r in one])
        row = [b, f"{step1:.1f}"]
        if two:
            t1, t2 = ph(one, lambda n: n.startswith("sort")), ph(two, lambda n: n.startswith("sort"))
            f = 2 * t2 / t1 - 1 if t1 > 0 else float("nan")
            row += [f"{t1:.2f} / {t2:.2f}", f"{100 * f:.0f}%", f"{100 * f * t1 / step1:.2f}%"]
        else:
            row += ["-"] * 3
        if ranks:
            step2 = med([r["ms"] for r in ranks])
            halo = ph(ranks, lambda n: n.startswith("halo"))
            wait = ph(ranks, lambda n: n == "halo:wait")
            row += [f"{halo - wait:.2f} / {wait:.2f}", f"{100 * (halo - wait) / step2:.2f}%",
                    f"{100 * halo / step2:.2f}%"]
        else:
            row += ["-"] * 3
        rows.append(row)
    if not rows:
        return
    print()
    print("| build | 1 x 1 ms/step | sort ms/step 1 x 1 / 1 x 2 | sort serial fraction | "
          "of the 1-thread step | halo work / MPI wait ms/step (2 x 1) | halo work / step | "
          "halo with waits / step |")
    print("|---|---|---|---|---|---|---|---|")
    for row in rows:
        print("| " + " | ".join(row) + " |")


main()
