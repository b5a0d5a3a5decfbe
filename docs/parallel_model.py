#!/usr/bin/python3
"""Strong and weak scaling model of chansph's domain decomposition (docs/parallel.md).

Time per step on P ranks (one core each; with threads, read "rank" as "core"):

    T(P) = t_c N / P                      computation (gather loops over the rank's particles)
         + G(P) (t_g + b / B)              ghosts: pack, unpack, and the bytes on the wire
         + m(P) alpha                      point-to-point messages (latency)
         + (3 log2 P + 4) alpha            three allreduces (dt, nu_max, and whether every
                                           migrating particle goes to a neighbour) and the
                                           migration's neighbour messages

G(P) ghosts per rank, for Px x Pz blocks of whole cell pencils (cells of size h along x and z,
the wall-normal direction whole; slabs are Px x 1), as the code counts them (dd.c,
ghost_pencils): a cut direction has a halo of R = 2 cells on each side, the z halo includes the
corners,

    G = [2 hx nzo + 2 hz (nxo + 2 hx)] pencils x (ly cx cz / dr^3) particles per pencil,
    nxo = ncol / Px, nzo = nplane / Pz, hx = R if Px > 1, hz = R if Pz > 1,

and Px x Pz is the code's own choice (the factorisation with the fewest ghosts whose blocks
have at least 2R columns and planes where cut): slabs while they have fewer ghosts, then
blocks; at most (ncol / 4) x (nplane / 4) ranks.

Constants measured on this machine (`chansph bench`, 3-D, 99 840 particles; tests/bench_halo.sh):
    t_c  per particle-step and core (1 rank x 1 thread) for the bench scene, the LES of
         les395_small, and the wide box's Wendland C4 kernel at h = 2 dr (the A/B's cost)
    t_g  local cost per ghost per step (the halo's own work on a 16-core node / its ghosts)
    b    bytes sent per ghost per step and m messages per step and rank: slabs and blocks,
         measured (docs/perf/halo_les395x4.csv, tests/bench_halo.sh)
Assumed for a cluster (InfiniBand HDR class): B = 10 GB/s per rank, alpha = 2 us.

usage: docs/parallel_model.py [--out docs/parallel_scaling.png]
       docs/parallel_model.py --measured CSV   (the ghosts of tests/bench_halo.sh against G)
"""
import argparse
import csv
import math

R = 2  # NBR_REACH: halo cells per side of a cut direction; a block needs 2 R where cut

# measured (docs/parallel.md, "Measured on this machine")
# (docs/performance.md, "Cost of the turbulence models and of the turbulent scenes")
T_C_MCF1 = 1.75 * 2 / 1659456  # s per particle-step per core, mcf1 (1 x 2 threads, 2026-12-01)
T_C_LES = 39e-3 * 2 / 41250  # s per particle-step per core, les395_small LES (1 x 2 threads)
T_C_C4 = 900.0 * 2 / 558e6  # wide box, Wendland C4 at h = 2 dr: 558 M particle-steps a turnover
#                             in 900 s on 2 threads (docs/validation/scheme_ab.md, delta_0.2)
# s per ghost per step: the halo's own work (migration, ghosts, refreshes; not the MPI waits) of
# a rank of mcf1 on 16 ranks x 1 thread of a 16-core node, 12.8 ms for 2 x 2 columns of ghosts
# (docs/perf/node16.csv)
GHOSTS_MCF1 = 2 * 2 * (3.140625 / 154) * 2.0 * 1.0 / 0.015625 ** 3
T_G = 12.8e-3 / GHOSTS_MCF1
# bytes per ghost per step and messages per step and rank, measured with tests/bench_halo.sh on
# les395_small x 4 (docs/perf/halo_les395x4.csv; 16 x 1 slabs and 4 x 4 blocks)
B_GHOST_SLAB = 220.0  # 1924 kB for 8 750 ghosts (16 x 1)
B_GHOST_BLOCK = 218.0  # 1689 kB for 7 734 ghosts (4 x 4)
MSG_SLAB = 14.2  # 2 neighbours: halo, 2 refreshes, counts, migration
MSG_BLOCK = 28.2  # 4 neighbours: x then z passes of each exchange, migration
# assumed cluster network
BW = 10e9
ALPHA = 2e-6

SCENES = {  # name: (lx, ly, lz, dr, h_over_dr, t_c)
    "mcf1 (1.66 M, quasi-DNS)": (3.140625, 2.0, 1.0, 0.015625, 1.3, T_C_MCF1),
    "wide box dr+ = 3 (1.21 M, C4)": (2.0, 2.0, 1.4, 1.0 / 60, 2.0, T_C_C4),
    "les550 (1.29 M, LES)": (2 * math.pi, 2.0, math.pi, 1.0 / 32, 1.3, T_C_LES),
}
RANKS = (2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096)


def cells(l, h):
    """Cells of size >= h along a periodic direction of length l (nbr_whole)."""
    return int(math.floor(l / h * (1 + 1e-12)))


def ghost_pencils(px, pz, ncol, nplane):
    """Ghost pencils per rank of Px x Pz blocks, or None if a block is thinner than 2 R."""
    if (px > 1 and ncol < 2 * R * px) or (pz > 1 and nplane < 2 * R * pz):
        return None
    hx, hz = (R if px > 1 else 0), (R if pz > 1 else 0)
    nxo, nzo = ncol / px, nplane / pz
    return 2.0 * hx * nzo + 2.0 * hz * (nxo + 2.0 * hx)


def choose(p, ncol, nplane):
    """The code's Px x Pz for p ranks (fewest ghosts; ties: more along x), or None."""
    best = None
    for px in range(p, 0, -1):
        if p % px:
            continue
        g = ghost_pencils(px, p // px, ncol, nplane)
        if g is not None and (best is None or g < best[0] - 1e-9):
            best = (g, px, p // px)
    return best


def step_time(p, lx, ly, lz, dr, hr, t_c, slabs=False):
    """(T, comm, px, pz) per step on p ranks, or None where the blocks do not fit."""
    h = hr * dr
    n = 1.0 / dr ** 3
    N = lx * ly * lz * n
    ncol, nplane = cells(lx, h), cells(lz, h)
    if p == 1:
        return t_c * N, 0.0, 1, 1
    if slabs:
        g = ghost_pencils(p, 1, ncol, nplane)
        best = None if g is None else (g, p, 1)
    else:
        best = choose(p, ncol, nplane)
    if best is None:
        return None
    gp, px, pz = best
    G = gp * ly * (lx / ncol) * (lz / nplane) * n
    b, m = (B_GHOST_SLAB, MSG_SLAB) if pz == 1 else (B_GHOST_BLOCK, MSG_BLOCK)
    comm = G * (T_G + b / BW) + m * ALPHA + (3 * math.log2(p) + 4) * ALPHA
    return t_c * N / p + comm, comm, px, pz


def table():
    rows = []
    for name, (lx, ly, lz, dr, hr, t_c) in SCENES.items():
        h = hr * dr
        ncol, nplane = cells(lx, h), cells(lz, h)
        t1 = step_time(1, lx, ly, lz, dr, hr, t_c)[0]
        print("%s: %d x %d cell pencils, slabs up to %d ranks, blocks up to %d; T(1) = %.2f s "
              "per step" % (name, ncol, nplane, ncol // (2 * R),
                            (ncol // (2 * R)) * (nplane // (2 * R)), t1))
        print("  %6s %9s %10s %10s %8s %10s %16s" % ("ranks", "Px x Pz", "T [ms]", "comm [ms]",
                                                   "comm %", "efficiency", "slabs: eff."))
        cross = None
        pmax = (ncol // (2 * R)) * (nplane // (2 * R))
        for p in [q for q in RANKS if q < pmax] + [pmax]:
            r = step_time(p, lx, ly, lz, dr, hr, t_c)
            if r is None:
                continue
            t, c, px, pz = r
            rs = step_time(p, lx, ly, lz, dr, hr, t_c, slabs=True)
            eff = t1 / (p * t)
            if cross is None and c > t - c:
                cross = p
            rows.append((name, p, t, c, eff, px, pz, None if rs is None else t1 / (p * rs[0])))
            print("  %6d %9s %10.2f %10.3f %7.1f%% %9.1f%% %16s"
                  % (p, "%d x %d" % (px, pz), 1e3 * t, 1e3 * c, 100 * c / t, 100 * eff,
                     "-" if rs is None else "%.1f%%" % (100 * t1 / (p * rs[0]))))
        print("  communication exceeds computation from about %d ranks" % cross if cross else
              "  communication stays below computation up to the last row (the most ranks: "
              "%d x %d blocks of 4 x 4 pencils)" % (ncol // (2 * R), nplane // (2 * R)))
    return rows


def weak():
    """Weak scaling: the box grows along x and z with the ranks (les395-size block per rank)."""
    print("weak scaling, blocks: 41 250 particles per rank (les395_small per rank, LES)")
    lx1, ly, lz1, dr, hr = 3.125, 2.0, 1.5625, 0.0625, 1.3
    t1 = step_time(1, lx1, ly, lz1, dr, hr, T_C_LES)[0]
    out = []
    for p in (1, 4, 16, 64, 256, 1024, 4096):
        q = int(round(math.sqrt(p)))
        r = step_time(p, lx1 * q, ly, lz1 * q, dr, hr, T_C_LES)
        t, c = r[0], r[1]
        out.append((p, t1 / t))
        print("  %5d ranks (%d x %d): %.1f ms per step, efficiency %.1f%% (comm %.2f ms)"
              % (p, r[2], r[3], 1e3 * t, 100 * t1 / t, 1e3 * c))
    return out


def measured(path):
    """The ghosts per owned particle of tests/bench_halo.sh's runs against the model's pencils,
    and the bytes per ghost and messages per step the model takes from them."""
    print("%6s %8s %9s %11s %11s %10s %12s %9s" % ("ranks", "layout", "Px x Pz", "ghosts/own",
                                                 "model", "B/ghost", "messages", "kB sent"))
    for r in csv.DictReader(open(path)):
        px, pz, ncol, nplane = (int(r[k]) for k in ("px", "pz", "ncol", "nplane"))
        gp = ghost_pencils(px, pz, ncol, nplane)
        model = gp / ((ncol / px) * (nplane / pz))
        bpg = 1e3 * float(r["kB_mean"]) / float(r["ghosts_mean"])
        print("%6s %8s %9s %11.3f %11.3f %10.0f %12s %9.0f"
              % (r["ranks"], r["layout"], "%d x %d" % (px, pz), float(r["ghosts_per_owned"]),
                 model, bpg, "%s (max %s)" % (r["messages_mean"], r["messages_max"]),
                 float(r["kB_mean"])))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--out", help="PNG of the strong-scaling efficiency")
    ap.add_argument("--measured", help="CSV of tests/bench_halo.sh: print it against the model")
    a, _ = ap.parse_known_args()  # bench_halo.sh passes its scene and --set too: not needed
    if a.measured:
        measured(a.measured)
        return
    print("constants: t_c %.3g us (mcf1), %.3g us (LES), %.3g us (C4) per particle-step; t_g "
          "%.3g us; %.0f / %.0f B per ghost and %.1f / %.1f messages per step (slabs / blocks); "
          "B = %.0f GB/s, alpha = %.0f us"
          % (1e6 * T_C_MCF1, 1e6 * T_C_LES, 1e6 * T_C_C4, 1e6 * T_G, B_GHOST_SLAB, B_GHOST_BLOCK,
             MSG_SLAB, MSG_BLOCK, BW / 1e9, 1e6 * ALPHA))
    rows = table()
    wk = weak()
    if a.out:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 2, figsize=(10, 4))
        for k, name in enumerate(SCENES):
            rr = [r for r in rows if r[0] == name]
            ax[0].semilogx([r[1] for r in rr], [100 * r[4] for r in rr], "o-", color="C%d" % k,
                           label=name)
            sl = [r for r in rr if r[7] is not None]
            ax[0].semilogx([r[1] for r in sl], [100 * r[7] for r in sl], ":", color="C%d" % k)
        ax[0].axhline(50, color="grey", lw=0.5)
        ax[0].set_xscale("log", base=2)
        ax[0].set_xlabel("ranks")
        ax[0].set_ylabel("strong-scaling efficiency [%]")
        ax[0].set_title("strong scaling: blocks (dotted: slabs only)")
        ax[0].legend(fontsize=8)
        ax[1].semilogx([w[0] for w in wk], [100 * w[1] for w in wk], "s-")
        ax[1].set_xscale("log", base=2)
        ax[1].set_xlabel("ranks")
        ax[1].set_ylabel("weak-scaling efficiency [%]")
        ax[1].set_title("weak scaling, 41 250 particles per rank")
        ax[1].set_ylim(0, 105)
        fig.tight_layout()
        fig.savefig(a.out, dpi=110)
        print("wrote %s" % a.out)


if __name__ == "__main__":
    main()
