"""chansph-stats summary: one screen (at most 30 lines) on a turbulent channel run against a DNS.

Also the last screen of jobs/quickstart.sh. It says, from the files alone:
  - is the flow turbulent, with the evidence: the -u'v'+ peak, the correlation coefficient
    R_uv = -<u'v'>/(u_rms v_rms) averaged over 30 <= y+ <= 100 (0.4-0.5 in wall turbulence,
    near 0 for particle noise), the quadrant split of u'v' where stats.nc has it (ejections Q2
    and sweeps Q4 dominate in wall turbulence) and the share of the stress at y+ = 30 that the
    resolved turbulence carries (where stats.nc has the momentum budget). The verdict is "yes"
    when the -u'v'+ peak is at least half the DNS's, R_uv >= 0.3 and (with quadrants) Q2 + Q4
    exceed twice |Q1 + Q3| at every level; "no" otherwise;
  - a table of the five quantities (U+, u_rms+, v_rms+, w_rms+, -u'v'+): the peak with its
    standard error and the largest deviation from the DNS over 10 < y+ < 150 relative to the
    DNS peak (the measure of `chansph compare`), for the run and, with --long, for a second
    (converged) run, each in wall units of its own u_tau (--u-tau, default the wall stress);
    a run averaged over fewer than 2 eddy turnovers is said to have standard errors far too
    small to judge by (its windows hold too few bursts).
The exit status is 0 whatever the verdict (a summary, not a test).
"""
import math

import numpy as np

from . import cli
from .compare import read_run
from .dns import QUANTITIES, read_dns
from .ncfile import open_nc

LO, HI = 10.0, 150.0
MAX_LINES = 30
SHORT = 2.0  # turnovers: a shorter average holds too few bursts for its standard errors


def evidence(path, ours, dns):
    """The turbulence indicators of the run at path (read_run's ours): a dict."""
    yp = ours["yplus"]
    e = {"uv_peak": float(np.nanmax(ours["-u'v'+"])),
         "uv_peak_dns": float(np.nanmax(dns["-u'v'+"]))}
    sel = (yp >= 30) & (yp <= 100)
    rms = ours["u_rms+"] * ours["v_rms+"]
    r = ours["-u'v'+"][sel] / np.where(rms[sel] > 0, rms[sel], np.nan)
    e["r_uv"] = float(np.nanmean(r)) if np.isfinite(r).any() else math.nan
    if "budget:reynolds_stress" in ours:
        k = int(np.argmin(np.abs(yp - 30.0)))
        e["resolved_30"] = ours["budget:reynolds_stress"][k] / ours["budget:total_stress"][k]
    with open_nc(path) as d:
        if "quadrants" in d.groups:
            g = d.groups["quadrants"]
            e["quadrants"] = [(float(y), np.ma.filled(g["uv_fraction"][lv, :].astype(float), np.nan))
                              for lv, y in enumerate(g["y_plus"][:])]
    return e


def turbulent(e):
    """The verdict on evidence e and the criteria it failed (list of words)."""
    failed = []
    if not e["uv_peak"] >= 0.5 * e["uv_peak_dns"]:
        failed.append("-u'v'+ peak below half the DNS's")
    if not e["r_uv"] >= 0.3:
        failed.append("R_uv below 0.3")
    for y, f in e.get("quadrants", []):
        if not (f[1] + f[3]) > 2 * abs(f[0] + f[2]):
            failed.append("Q2 + Q4 do not dominate at y+ %.0f" % y)
    return not failed, failed


def evidence_lines(e):
    ok, failed = turbulent(e)
    out = ["Is the flow turbulent? %s" % ("yes" if ok else "no (" + "; ".join(failed) + ")")]
    words = "  -u'v'+ peak %.2f (DNS %.2f); R_uv(30<=y+<=100) %.2f (wall turbulence 0.4-0.5)" % (
        e["uv_peak"], e["uv_peak_dns"], e["r_uv"])
    if "resolved_30" in e:
        words += "; resolved share of the stress at y+ 30: %.0f%%" % (100 * e["resolved_30"])
    out.append(words)
    if e.get("quadrants"):
        out.append("  share of u'v' carried by ejections Q2 + sweeps Q4: " + ", ".join(
            "%.2f at y+ %.0f" % (f[1] + f[3], y) for y, f in e["quadrants"]))
    return out


def peaks(ours, dns):
    """Per quantity: (peak, its standard error, max deviation over LO < y+ < HI / DNS peak)."""
    yp = ours["yplus"]
    sel = (yp > LO) & (yp < HI) & (yp >= dns["yplus"][0]) & (yp <= dns["yplus"][-1])
    out = {}
    for q in QUANTITIES:
        k = int(np.nanargmax(ours[q]))
        ref = np.interp(yp, dns["yplus"], dns[q])
        dpk = float(np.nanmax(np.abs(dns[q])))
        dev = float(np.nanmax(np.abs(ours[q] - ref)[sel])) / dpk if sel.any() else math.nan
        out[q] = (float(ours[q][k]), float(ours[q + "_se"][k]), dev)
    return out


def turnovers(path):
    """The averaging span in eddy turnover times delta/u_tau (u_tau of the driving force, or of
    the wall stress where there is none)."""
    with open_nc(path) as d:
        a = {k: d.getncattr(k) for k in d.ncattrs()}
    ut = float(a.get("u_tau_force", math.nan))
    if not ut > 0:
        ut = float(a.get("u_tau_wall", math.nan))
    return (float(a["average_end"]) - float(a["average_start"])) * ut / float(a["delta"])


def table_lines(runs, dns):
    """runs: [(label, peaks)]; one row per quantity."""
    rows = ["%-9s" % "" + "".join("| %-28s" % lab for lab, _ in runs) + "| DNS",
            "%-9s" % "quantity" + "| %-28s" % "peak +- stderr   max dev" * len(runs) + "| peak"]
    for q in QUANTITIES:
        row = "%-9s" % q
        for _, p in runs:
            pk, se, dev = p[q]
            row += "| %6.3f +- %-6s %7s    " % (pk, ("%.3f" % se) if math.isfinite(se) else "-",
                                              ("%.1f%%" % (100 * dev)) if math.isfinite(dev) else "-")
        rows.append(row + "| %.3f" % float(np.nanmax(dns[q])))
    return rows


def run_label(path):
    return "%.3g turnovers" % turnovers(path)


def describe(path):
    """One line on what ran, from the file's attributes."""
    with open_nc(path) as d:
        a = {k: d.getncattr(k) for k in d.ncattrs()}
    ut, nu, delta = float(a.get("u_tau_force", math.nan)), float(a["nu"]), float(a["delta"])
    box = "%.3g x 2 x %.3g" % (float(a.get("lx", math.nan)) / delta, float(a.get("lz", math.nan)) / delta)
    return ("%s: Re_tau %.0f (driving force), %s, dr+ = %.2g, box %s delta, %d particles"
            % (path, ut * delta / nu, "LES" if int(a.get("les", 0)) else
               "quasi-DNS (no turbulence model)", float(a["dr"]) * ut / nu, box,
               int(a.get("n_fluid", 0))))


def summary_lines(args):
    dns = read_dns(args.dns)
    ours = read_run(args.stats, args.u_tau)
    lines = [describe(args.stats)] + evidence_lines(evidence(args.stats, ours, dns))
    runs = [("this run, " + run_label(args.stats), peaks(ours, dns))]
    units = ["this run: %s" % ours["u_tau_label"]]
    if args.long:
        long_run = read_run(args.long, args.u_tau)
        runs.append(("long run, " + run_label(args.long), peaks(long_run, dns)))
        units.append("long run (%s): %s" % (args.long, long_run["u_tau_label"]))
    lines.append("Peaks against %s (Re_tau %.0f); max dev = largest |ours - DNS| over %g < y+ < %g"
                 % (dns["name"], dns["re_tau"], LO, HI))
    lines.append("relative to the DNS peak; wall units of each run's own u_tau:")
    lines += ["  " + u for u in units]
    lines += table_lines(runs, dns)
    for name, path in (("this run", args.stats), ("the long run", args.long)):
        if path and turnovers(path) < SHORT:
            lines.append("(%s spans %.2g turnovers, less than %g: its standard errors are far too "
                         "small to judge by)" % (name, turnovers(path), SHORT))
    return lines


def main(argv, prog="chansph-stats summary"):
    p = cli.parser(prog, __doc__, raw=True)
    p.add_argument("stats", help="stats.nc of the run")
    p.add_argument("--dns", required=True, help="one file of a DNS set (as chansph compare)")
    p.add_argument("--long", help="stats.nc of a converged run to show beside it")
    p.add_argument("--u-tau", default="wall", metavar="wall|force|VALUE",
                   help="u_tau of the wall units (default: the wall stress of each run)")
    args = p.parse_args(argv)
    for f in (args.stats, args.long):
        if f:
            cli.regular_file(f, "statistics file")
    lines = summary_lines(args)
    print("\n".join(lines))
    if len(lines) > MAX_LINES:  # a guard on the promise of one screen
        raise cli.InputError("summary: %d lines, more than one screen (%d)" % (len(lines), MAX_LINES))
    return 0
