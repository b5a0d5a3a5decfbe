#!/usr/bin/python3
"""The Reynolds-stress budget comparison (chansph-stats rs_budget, budget_compare.py, and its
part of `chansph compare`) on synthetic stats.nc files whose budgets are the MKM Re_tau = 180
balances themselves, in physical units (u_tau = 2 m/s, nu = 0.01 m^2/s: every term is
u_tau^4/nu = 1600 times its wall-unit value), so the comparison must come out zero.

usage: stats_tools_rs_budget.py ROOT WORK PART
  PART = folded    fold = 1, les = 1 (model = 0): the table at y+ 10, 15, 30, 50 and
                   rs_budget.csv (every bin) differ from MKM by < 1e-6 of the peak; the nearest
                   bins are within half a bin of the levels; the 5 PNGs are written; the
                   function API agrees; a wrong u_tau (--u-tau 1) does not agree
         unfolded  fold = 0 over both halves: the upper half mirrored (uv terms with the
                   opposite sign) and, with a symmetric bin layout, averaged with the lower one
                   (the halves carry opposite errors that only the average cancels); an
                   asymmetric layout is mirrored bin by bin
         compare   `chansph-stats compare` prints the budget table and writes rs_budget.csv
                   and the PNGs for a file with rsb_ variables, and nothing of it without them
         errors    a file without rsb_ variables, one lacking one variable, bad --y-plus, a
                   missing --dns-dir, a missing file: "error: ...", exit 1, no traceback
Prints PASS or FAIL lines; exit status 1 on any FAIL.
"""
import csv
import math
import os
import subprocess
import sys

import netCDF4
import numpy as np

ROOT, WORK, PART = sys.argv[1], sys.argv[2], sys.argv[3]
sys.path.insert(0, os.path.join(ROOT, "stats", "python"))
from chansph_stats import budget_compare as bc  # noqa: E402
from passfail import check, finish  # noqa: E402

TOOL = os.path.join(ROOT, "stats", "python", "chansph-stats")
BAL = os.path.join(ROOT, "stats", "dns", "mkm1999", "balances")
MEANS = os.path.join(ROOT, "stats", "dns", "mkm1999", "chan180.means")
NU, UT, RE = 0.01, 2.0, 178.12
DELTA = RE * NU / UT
SCALE = UT ** 4 / NU  # physical = wall units * SCALE
LEVELS = (10.0, 15.0, 30.0, 50.0)
COMP = ("uu", "vv", "ww", "uv", "k")
TOL = 1e-6


def run(*args):
    p = subprocess.run([TOOL] + list(args), capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def mkm(c):
    """The MKM balance of component c: {column: array} (wall units)."""
    with open(os.path.join(BAL, "chan180.%sbal" % c)) as f:
        rows = [[float(x) for x in line.split()] for line in f
                if line.strip() and not line.startswith("#")]
    return dict(zip(bc.DNS_COLUMNS, np.array(rows).T))


def terms_at(c, yp):
    """Our terms (wall units) that reproduce MKM at y+ yp."""
    d = mkm(c)

    def f(*cols):
        return np.interp(yp, d["y+"], sum(d[k] for k in cols))
    z = np.zeros(len(yp))
    return {"pressure": f("p-strain", "p-diff"), "viscous": f("dissip", "v-diff"), "model": z,
            "wall": z, "drive": z, "transfer": f("produc", "t-diff"), "production": f("produc"),
            "transport": f("t-diff"), "rate": z, "closure": f("bal")}


def peak(c):
    d = mkm(c)
    return max(np.max(np.abs(d[k])) for k in bc.DNS_COLUMNS[2:])


def var(d, name, data):
    v = d.createVariable(name, "f8", ("y",))
    v[:] = data
    v.units = "m^2/s^3" if name.startswith("rsb_") else "m"


def write(path, y, fold, les=0, budgets=True, skew=None, drop=None):
    """A stats.nc with bins y_mean = y. skew(c, t, upper): an error added to the term (wall
    units) in the upper (True) or lower half; drop: a variable left out."""
    upper = y > DELTA
    yp = np.where(upper, 2 * DELTA - y, y) * UT / NU
    n = len(y)
    with netCDF4.Dataset(path, "w") as d:
        for k, v in dict(nu=NU, delta=DELTA, u_tau=UT, u_tau_wall=UT, u_tau_force=UT, fold=fold,
                         les=les, n_windows=8, average_start=10.0, average_end=20.0,
                         re_tau=RE).items():
            d.setncattr(k, v)
        d.createDimension("y", n)
        var(d, "y", y)
        var(d, "y_mean", y)
        means = np.array([[float(x) for x in line.split()] for line in open(MEANS)
                          if line.strip() and not line.startswith("#")])
        var(d, "u_mean", UT * np.interp(yp, means[:, 1], means[:, 2]))
        var(d, "u_mean_stderr", np.full(n, 1e-3))
        for s, val in (("uu", 4 * UT ** 2), ("vv", 0.5 * UT ** 2), ("ww", UT ** 2),
                       ("uv", np.where(upper, 0.7, -0.7) * UT ** 2 * (1 - yp / RE))):
            var(d, s, np.full(n, 1.0) * val)
            var(d, s + "_stderr", np.full(n, 1e-3))
        if not budgets:
            return
        for c in COMP:
            sign = np.where(upper, -1.0, 1.0) if c == "uv" else 1.0
            se = 1e-3 * peak(c) * SCALE
            for t, v in terms_at(c, yp).items():
                if t == "model" and not les:
                    continue
                err = 0.0 if skew is None else np.where(upper, skew(c, t, True), skew(c, t, False))
                name = "rsb_%s_%s" % (c, t)
                if name != drop:
                    var(d, name, sign * (v + err) * SCALE)
                var(d, name + "_stderr", np.full(n, se))


def table_rows(out):
    """{(c, level, term): (bin y+, ours, 2se, dns, diff)} of the printed tables."""
    rows, c = {}, None
    for line in out.splitlines():
        if line.startswith("rs budget "):
            c = line.split()[2].rstrip(":")
            continue
        f = line.split()
        if c and len(f) >= 7:
            try:
                lev, ybin = float(f[0]), float(f[1])
            except ValueError:
                continue
            vals = [math.nan if x == "-" else float(x) for x in f[3:7]]
            rows[(c, lev, f[2])] = [ybin] + vals
    return rows


def check_table(out, dy, what):
    rows = table_rows(out)
    mapped = [k for k, r in rows.items() if math.isfinite(r[3])]
    check(len(mapped) == len(COMP) * len(LEVELS) * 9,
          "%s: %d table rows with a DNS value (5 components x 4 levels x 9)" % (what, len(mapped)))
    worst = max((abs(rows[k][4]) / peak(k[0]) for k in mapped), default=math.inf)
    check(worst <= 1e-4, "%s: table ours - DNS at most %.1e of the peak (printed to 4 decimals)"
          % (what, worst))
    near = max(abs(r[0] - k[1]) for k, r in rows.items())
    check(near <= 0.5 * dy + 0.01, "%s: the table's bins within half a bin (%.2f) of the levels: "
          "%.3f" % (what, 0.5 * dy, near))


def check_csv(path, what, yplus=None):
    with open(path) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    worst, n = 0.0, 0
    for r in rows:
        dns = float(r["dns"])
        if math.isfinite(dns):
            n += 1
            worst = max(worst, abs(float(r["ours"]) - dns) / peak(r["component"]))
    check(n > 0 and worst <= TOL, "%s: rs_budget.csv, %d values with a DNS: max |ours - DNS| = "
          "%.2e of the peak (tolerance %g)" % (what, n, worst, TOL))
    if yplus is not None:
        got = sorted({float(r["y+"]) for r in rows})
        ok = len(got) == len(yplus) and np.allclose(got, np.sort(yplus), rtol=1e-7)
        check(ok, "%s: rs_budget.csv has the expected %d bins (mirrored), %d found" %
              (what, len(yplus), len(got)))


def check_api(path, what):
    ours, dns = bc.read_budgets(path), bc.read_dns()
    worst = 0.0
    for lev in LEVELS:
        i = int(np.nanargmin(np.abs(ours["yplus"] - lev)))
        for c in COMP:
            for row in bc.ROWS:
                got = bc.row_values(ours, dns, c, row)
                if got is None or not math.isfinite(got[2][i]):
                    continue
                worst = max(worst, abs(got[0][i] - got[2][i]) / peak(c))
    check(worst <= TOL, "%s: read_budgets/row_values at the levels: max |ours - DNS| = %.2e of the "
          "peak" % (what, worst))


def folded():
    n = 60
    dy = RE / n
    f = os.path.join(WORK, "folded.nc")
    write(f, (np.arange(n) + 0.5) * DELTA / n, fold=1, les=1)
    out_dir = os.path.join(WORK, "out")
    rc, out, err = run("rs_budget", f, "--out", out_dir)
    print(out + err)
    check(rc == 0, "rs_budget folded: exit %d" % rc)
    check_table(out, dy, "folded")
    check(" model " in out, "folded, les = 1: the model row is printed")
    check_csv(os.path.join(out_dir, "rs_budget.csv"), "folded", (np.arange(n) + 0.5) * dy)
    pngs = [os.path.join(out_dir, "rs_budget_%s.png" % c) for c in COMP]
    check(all(os.path.getsize(p) > 10000 for p in pngs if os.path.isfile(p)) and
          all(os.path.isfile(p) for p in pngs), "folded: the 5 PNGs rs_budget_<c>.png written")
    check_api(f, "folded")
    rc, out, _ = run("rs_budget", f, "--u-tau", "1", "--y-plus", "15")
    rows = table_rows(out)
    check(rc == 0 and abs(rows[("uu", 15.0, "production")][4]) > 0.01,
          "--u-tau 1 (wrong wall units): production of uu at y+ 15 differs by %.3f" %
          rows[("uu", 15.0, "production")][4])


def unfolded():
    n = 120
    dy = 2 * RE / n
    f = os.path.join(WORK, "unfolded.nc")

    def skew(c, t, up):  # opposite errors in the two halves: only their average is MKM's
        return (1 if up else -1) * 0.05 * peak(c)
    write(f, (np.arange(n) + 0.5) * 2 * DELTA / n, fold=0, skew=skew)
    out_dir = os.path.join(WORK, "out_sym")
    rc, out, err = run("rs_budget", f, "--out", out_dir)
    print(out + err)
    check(rc == 0, "rs_budget unfolded: exit %d" % rc)
    check_table(out, dy, "unfolded, symmetric bins (halves averaged)")
    check(" model " not in out, "unfolded, les = 0: no model row")
    check_csv(os.path.join(out_dir, "rs_budget.csv"), "unfolded, symmetric bins",
              (np.arange(n // 2) + 0.5) * dy)
    check_api(f, "unfolded, symmetric bins")
    g = os.path.join(WORK, "unfolded_shifted.nc")
    y = (np.arange(n) + 0.3) * 2 * DELTA / n
    write(g, y, fold=0)
    out_dir = os.path.join(WORK, "out_shift")
    rc, out, err = run("rs_budget", g, "--out", out_dir, "--u-tau", "force")
    check(rc == 0, "rs_budget unfolded, shifted bins, --u-tau force: exit %d" % rc)
    check_table(out, dy, "unfolded, shifted bins (mirrored bin by bin)")
    check_csv(os.path.join(out_dir, "rs_budget.csv"), "unfolded, shifted bins",
              np.where(y > DELTA, 2 * DELTA - y, y) * UT / NU)


def compare():
    f = os.path.join(WORK, "with.nc")
    write(f, (np.arange(60) + 0.5) * DELTA / 60, fold=1)
    out_dir = os.path.join(WORK, "cmp_with")
    rc, out, err = run("compare", f, "--dns", MEANS, "--out", out_dir)
    print(out[-3000:] + err)
    check(rc == 0, "compare with rsb_: exit %d" % rc)
    check(all("rs budget %s:" % c in out for c in COMP), "compare prints the 5 budget tables")
    check(out.find("wrote %s/compare.csv" % out_dir) < out.find("rs budget uu:"),
          "compare: the budget table after the existing output")
    check_table(out, RE / 60, "compare")
    check(all(os.path.isfile(os.path.join(out_dir, n)) for n in
              ["rs_budget.csv"] + ["rs_budget_%s.png" % c for c in COMP]),
          "compare writes rs_budget.csv and the 5 PNGs into its output directory")
    g = os.path.join(WORK, "without.nc")
    write(g, (np.arange(60) + 0.5) * DELTA / 60, fold=1, budgets=False)
    out_dir = os.path.join(WORK, "cmp_without")
    rc, out2, err = run("compare", g, "--dns", MEANS, "--out", out_dir)
    check(rc == 0 and "rs budget" not in out2 and "Reynolds-stress" not in out2 and
          not any(n.startswith("rs_budget") for n in os.listdir(out_dir)),
          "compare without rsb_: exit %d, no budget output or files" % rc)
    rc, out3, _ = run("compare", f, "--dns", MEANS, "--out", os.path.join(WORK, "cmp_np"),
                      "--no-plots")
    check(rc == 0 and "rs budget uu:" in out3 and not os.path.exists(
        os.path.join(WORK, "cmp_np", "rs_budget_uu.png")),
        "compare --no-plots: the table, no budget PNG")


def errors():
    bare = os.path.join(WORK, "bare.nc")
    write(bare, (np.arange(20) + 0.5) * DELTA / 20, fold=1, budgets=False)
    lack = os.path.join(WORK, "lack.nc")
    write(lack, (np.arange(20) + 0.5) * DELTA / 20, fold=1, drop="rsb_vv_rate")
    text = os.path.join(WORK, "text.nc")
    with open(text, "w") as f:
        f.write("not netCDF\n")
    good = os.path.join(WORK, "good.nc")
    write(good, (np.arange(20) + 0.5) * DELTA / 20, fold=1)
    check(bc.read_budgets(bare) is None, "read_budgets of a file without rsb_: None")
    cases = [
        (["rs_budget", bare], "bare.nc: no Reynolds-stress budget variables"),
        (["rs_budget", lack], "lack.nc: no variable 'rsb_vv_rate'"),
        (["rs_budget", os.path.join(WORK, "missing.nc")], "missing.nc: cannot open: No such file"),
        (["rs_budget", text], "text.nc: cannot open as netCDF"),
        (["rs_budget", lack, "--y-plus", "5,x"], "--y-plus 5,x: expected y+ values"),
        (["rs_budget", lack, "--dns-dir", os.path.join(WORK, "nodir")],
         "nodir: cannot open the MKM balances directory"),
        (["rs_budget", lack, "--dns-dir", WORK], "no MKM balance file chanNNN.uubal"),
        (["rs_budget", good, "--u-tau", "x"], "--u-tau x: expected force, wall or a number"),
        (["rs_budget"], "the following arguments are required: stats"),
    ]
    for args, want in cases:
        rc, out, err = run(*args)
        first = err.splitlines()[0] if err else ""
        ok = (rc == 1 and first.startswith("error: ") and want in first and
              "Traceback" not in out + err)
        check(ok, "%s: exit %d, %r" % (" ".join(os.path.basename(a) for a in args), rc, first))


os.makedirs(WORK, exist_ok=True)
{"folded": folded, "unfolded": unfolded, "compare": compare, "errors": errors}[PART]()
finish(PART)
