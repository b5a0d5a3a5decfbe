"""Peaks of the Reynolds stresses of runs over chosen time ranges, side by side with a DNS.

usage: chansph-stats window_peaks --dns FILE [--units wall|force]
                                 LABEL=RUN_DIR[+RUN_DIR...]@T0:T1 ...

For each spec, the windows of stats.nc inside [T0, T1] (delta/u_tau; chained runs as in
error_vs_time) are merged from their raw sums (old and new stats.nc formats alike), in wall
units of the windows' mean wall shear stress (default, as `chansph extract --units wall`) or of
the force balance (u_tau^2 = delta f). Printed: the peaks of -u'v'+, u_rms+, v_rms+ and w_rms+ with
their deviation from the DNS peak, and the range of the relative deviation of v_rms+ and w_rms+
over 20 < y+ < 150 (the resolution series' measures). With --plot FILE, the profiles of U+,
u_rms+, v_rms+, w_rms+ and -u'v'+ of every spec against the DNS in one PNG. Used for the LES
against quasi-DNS rows and the profile figure of docs/validation/turbulent_channel.md.
"""

import numpy as np

from . import cli
from .dns import deviation, range_deviation, read_dns
from .merge import window_profile

PEAKS = ("-u'v'+", "u_rms+", "v_rms+", "w_rms+")


def main(argv, prog):
    ap = cli.parser(prog, __doc__)
    ap.add_argument("runs", nargs="+", help="LABEL=RUN_DIR[+RUN_DIR...]@T0:T1")
    ap.add_argument("--dns", required=True)
    ap.add_argument("--units", choices=("wall", "force"), default="wall")
    ap.add_argument("--plot", help="write the profiles against the DNS to this PNG")
    a = ap.parse_args(argv)
    dns = read_dns(a.dns)
    rows = []
    for spec in a.runs:
        label, dirs, t0, t1 = cli.run_spec(spec)
        prof, got = window_profile(dirs, t0, t1, a.units)
        rows.append((label, got, prof))
    print(f"# peaks (deviation from {dns['name']}) and the v_rms+, w_rms+ deviation over "
          f"20 < y+ < 150; {a.units} units")
    print(f"# {'run':<16} {'t':>11} " + " ".join(f"{q:>13}" for q in PEAKS) +
          f" {'v_rms+ 20-150':>14} {'w_rms+ 20-150':>14}")
    for label, got, prof in rows:
        cells = [f"{np.nanmax(prof[q]):5.2f} ({100 * deviation(prof, dns, q, 'peak'):+4.0f}%)"
                 for q in PEAKS]
        for q in ("v_rms+", "w_rms+"):
            rel = range_deviation(prof, dns, q)
            cells.append(f"{100 * rel.min():+5.0f}..{100 * rel.max():+4.0f}%")
        print(f"  {label:<16} {got[0]:5.2f}-{got[1]:5.2f} " + " ".join(f"{c:>13}" for c in cells))
    if a.plot:
        plot(a.plot, rows, dns, a.units)


def plot(path, rows, dns, units):
    """U+ (log y+) and the four stresses (linear y+) of every run against the DNS."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    qs = ("U+",) + PEAKS
    fig, axes = plt.subplots(1, len(qs), figsize=(3.6 * len(qs), 3.8))
    for ax, q in zip(axes, qs):
        ax.plot(dns["yplus"], dns[q], "k-", lw=2, alpha=0.35, label=dns["name"])
        for label, got, prof in rows:
            ok = np.isfinite(prof[q]) & (prof["yplus"] > 0)
            ax.plot(prof["yplus"][ok], prof[q][ok], "-", lw=1.2,
                    label=f"{label}, t = {got[0]:g}-{got[1]:g}")
        ax.set_xscale("log" if q == "U+" else "linear")
        ax.set_xlim(1 if q == "U+" else 0, dns["yplus"].max())
        ax.set_xlabel("y+")
        ax.set_title(q)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=6, loc="upper left")
    fig.suptitle(f"windows averaged from their raw sums; {units} units", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")
