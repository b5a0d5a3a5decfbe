"""Per-window turbulence indicators of a run: is it turbulent, and is it decaying?

usage: chansph-stats windows STATS.nc [--every K] [--u-tau U]

For every averaging window (stats.window) of stats.nc, from its raw sums (group eulerian):
the -u'v'+ peak and where it lies, the u_rms+ and v_rms+ peaks, the correlation coefficient
R_uv = -u'v' / (u_rms v_rms) averaged over 30 <= y+ <= 100 (about 0.4-0.5 in wall turbulence,
near 0 for particle noise), the bulk velocity U_b+, and with the momentum budget the share of
the stress that the resolved turbulence carries at y+ = 30. Wall units use u_tau from the
force balance of the whole run (or --u-tau). With fold = 0 the upper half is mirrored.
A run whose -u'v'+ peak falls window after window is decaying; one near the DNS (0.72 at
Re_tau = 180, 0.84 at 395) with R_uv about 0.45 is sustaining resolved turbulence.
"""
from . import cli
from .merge import window_values
from .ncfile import read_windows


def main(argv, prog):
    ap = cli.parser(prog, __doc__)
    ap.add_argument("stats")
    ap.add_argument("--every", type=cli.number(int, 1), default=1, help="print every K-th window")
    ap.add_argument("--u-tau", type=cli.number(float, 0), default=0.0)
    a = ap.parse_args(argv)
    r = read_windows(a.stats)
    win, mom, pln, delta, nu = r["win"], r["mom"], r["pln"], r["delta"], r["nu"]
    ut = a.u_tau if a.u_tau > 0 else r["ut"]
    print(f"# {a.stats}: {len(win)} windows, u_tau = {ut:.4g} (force balance), "
          f"Re_tau = {ut * delta / nu:.1f}")
    print(f"# {'t0':>7} {'t1':>7} {'-uv+pk':>7} {'y+pk':>6} {'urms+pk':>7} {'vrms+pk':>7} "
          f"{'R_uv':>6} {'U_b+':>6}")
    rows = [i for i in range(0, len(win), a.every) if r["done"][i]]
    vals = window_values(mom[rows], pln[rows] if pln is not None else [None] * len(rows),
                         delta, r["fold"], ut, nu)
    for i, v in zip(rows, vals):
        print(f"  {win[i, 0]:7.3f} {win[i, 1]:7.3f} {v['uv_peak']:7.3f} {v['y_peak']:6.1f} "
              f"{v['urms']:7.3f} {v['vrms']:7.3f} {v['ruv']:6.3f} {v['ub']:6.2f}")
