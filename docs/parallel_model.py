#!/usr/bin/python3
"""Strong and weak scaling model of chansph's domain decomposition (docs/parallel.md).

Time per step on P ranks (one core each; with threads, read "rank" as "core"):

    T(P) = t_c N / P                      computation (gather loops over the rank's particles)
         + G(P) (t_g + b / B)              ghosts: pack, unpack, sort, and the bytes on the wire
         + m(P) alpha                      point-to-point messages (latency)
         + (3 log2 P + 4) alpha            three allreduces (dt, nu_max, and whether every
                                           migrating particle goes to a neighbour) and the
                                           migration's four neighbour messages (counts, records)

G(P) ghosts per rank: slabs of whole cell columns along x (implemented):
    G = 2 sides * w * ly * lz * n,   w = NBR_REACH cells of size ~h = 2 h,  n = 1 / dr^3,
independent of P: the halo does not shrink when the slabs get thinner. x-z blocks
(Px x Pz ranks, not implemented) for comparison:
    G = (2 w lz / Pz + 2 w lx / Px + 4 w^2) ly n.
Slabs stop at P = ncol / (2 NBR_REACH) (each rank owns 4 columns or more).

Constants measured on this machine (tests/bench_mpi.sh; `chansph bench`, 3-D, 99 840 particles):
    t_c  per particle-step and core (1 rank x 1 thread) for the bench scene, and for the LES of
         les395_small (107 ms per step on 2 threads for 41 250 particles)
    t_g  local cost per ghost per step (mean halo time of the 2-rank bench / its ghosts)
    b    bytes per ghost per step (kB sent per rank per step / ghosts)
Assumed for a cluster (InfiniBand HDR class): B = 10 GB/s per rank, alpha = 2 us.

usage: docs/parallel_model.py [--out docs/parallel_scaling.png]
"""
import argparse
import math

# measured (docs/parallel.md, "Measured on this machine")
T_C_BENCH = 194.3e-3 / 99840  # s per particle-step per core, bench scene (1 x 1)
T_C_LES = 107e-3 * 2 / 41250  # s per particle-step per core, les395_small LES (1 x 2 threads)
GHOSTS_BENCH = 2 * 2 * (1.6 / 49) * 1.0 * 1.0 / 0.025 ** 3  # 2 sides x 2 cols x ly x lz x n
# s per ghost per step: the halo's own work (migration, ghosts, refreshes; not the MPI waits) of
# a rank of mcf1 on 16 ranks x 1 thread of a 16-core node, 12.8 ms for 2 x 2 columns of ghosts
# (docs/perf/node16.csv; it was 4.07 ms for the bench scene's ghosts on 2 ranks
# before the halo was threaded and lost its ghost sort, 0.49 us per ghost)
GHOSTS_MCF1 = 2 * 2 * (3.140625 / 154) * 2.0 * 1.0 / 0.015625 ** 3
T_G = 12.8e-3 / GHOSTS_MCF1
B_GHOST = 1479.8e3 / GHOSTS_BENCH  # bytes per ghost per step (9 doubles built, 12 refreshed)
MSG_SLAB = 8  # point-to-point messages per step and rank (bench, 2 ranks)
# assumed cluster network
BW = 10e9
ALPHA = 2e-6

SCENES = {  # name: (lx, ly, lz, dr, h_over_dr, t_c)
    "mcf1 (1.66 M, quasi-DNS)": (3.140625, 2.0, 1.0, 0.015625, 1.3, T_C_BENCH),
    "les1000 (4.98 M, LES)": (6.28, 2.0, 3.14, 0.02, 1.3, T_C_LES),
}


def columns(lx, h):
    return int(math.floor(lx / h * (1 + 1e-12)))


def step_time(p, lx, ly, lz, dr, hr, t_c, blocks=False):
    h = hr * dr
    n = 1.0 / dr ** 3
    N = lx * ly * lz * n
    w = 2 * h
    if p == 1:
        return t_c * N, 0.0
    if not blocks:
        g = 2 * w * ly * lz * n
        m = MSG_SLAB
    else:
        px = max(1, int(round(math.sqrt(p * lx / lz))))
        pz = max(1, p // px)
        g = (2 * w * lz / pz + 2 * w * lx / px + 4 * w * w) * ly * n
        m = 4 * MSG_SLAB  # 8 neighbours instead of 2
    comm = g * (T_G + B_GHOST / BW) + m * ALPHA + (3 * math.log2(p) + 4) * ALPHA
    return t_c * N / p + comm, comm


def table():
    rows = []
    for name, (lx, ly, lz, dr, hr, t_c) in SCENES.items():
        ncol = columns(lx, hr * dr)
        pmax = ncol // 4
        t1, _ = step_time(1, lx, ly, lz, dr, hr, t_c)
        print("%s: %d cell columns, slabs up to %d ranks; T(1) = %.2f s per step"
              % (name, ncol, pmax, t1))
        print("  %6s %10s %10s %8s %10s   %s" % ("ranks", "T [ms]", "comm [ms]", "comm %",
                                                  "efficiency", "decomposition"))
        cross = None
        for p in (2, 4, 8, 16, 32, 64, 128, 256, 512, 1000):
            blocks = p > pmax
            t, c = step_time(p, lx, ly, lz, dr, hr, t_c, blocks)
            eff = t1 / (p * t)
            if cross is None and c > t - c:
                cross = p
            rows.append((name, p, t, c, eff, blocks))
            print("  %6d %10.2f %10.2f %7.1f%% %9.1f%%   %s" % (p, 1e3 * t, 1e3 * c, 100 * c / t,
                                                                 100 * eff,
                                                                 "x-z blocks (model)" if blocks
                                                                 else "slabs"))
        print("  communication exceeds computation from about %s ranks" % (cross or "> 1000"))
    return rows


def weak():
    """Weak scaling: the box grows along x with the ranks (les395-size slab per rank)."""
    print("weak scaling, slabs: 41 250 particles per rank (les395_small per rank, LES)")
    lx1, ly, lz, dr, hr = 3.125, 2.0, 1.5625, 0.0625, 1.3
    t1, _ = step_time(1, lx1, ly, lz, dr, hr, T_C_LES)
    out = []
    for p in (1, 2, 8, 32, 128, 512, 1000):
        t, c = step_time(p, lx1 * p, ly, lz, dr, hr, T_C_LES)
        out.append((p, t1 / t))
        print("  %5d ranks: %.1f ms per step, efficiency %.1f%% (comm %.2f ms)"
              % (p, 1e3 * t, 100 * t1 / t, 1e3 * c))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--out", help="PNG of the strong-scaling efficiency")
    a = ap.parse_args()
    print("constants: t_c %.3g us (bench), %.3g us (LES) per particle-step; t_g %.3g us and "
          "%.0f B per ghost per step; B = %.0f GB/s, alpha = %.0f us"
          % (1e6 * T_C_BENCH, 1e6 * T_C_LES, 1e6 * T_G, B_GHOST, BW / 1e9, 1e6 * ALPHA))
    rows = table()
    wk = weak()
    if a.out:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 2, figsize=(10, 4))
        for name in SCENES:
            ps = [r[1] for r in rows if r[0] == name]
            ax[0].semilogx(ps, [100 * r[4] for r in rows if r[0] == name], "o-", label=name)
        ax[0].axhline(50, color="grey", lw=0.5)
        ax[0].set_xlabel("ranks")
        ax[0].set_ylabel("strong-scaling efficiency [%]")
        ax[0].set_title("strong scaling (slabs, then x-z blocks)")
        ax[0].legend()
        ax[1].semilogx([w[0] for w in wk], [100 * w[1] for w in wk], "s-")
        ax[1].set_xlabel("ranks")
        ax[1].set_ylabel("weak-scaling efficiency [%]")
        ax[1].set_title("weak scaling, 41 250 particles per rank")
        ax[1].set_ylim(0, 105)
        fig.tight_layout()
        fig.savefig(a.out, dpi=110)
        print("wrote %s" % a.out)


if __name__ == "__main__":
    main()
