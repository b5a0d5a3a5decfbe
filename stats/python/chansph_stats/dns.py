"""The DNS data sets we ship in stats/dns/ (or files in the same formats), and how far a
profile lies from one.

read_dns(FILE) reads one file of a set:
  Moser, Kim & Mansour 1999: chanNNN.means (+ companion chanNNN.reystress, found by name)
  Lee & Moser 2015:          LM_Channel_NNNN_mean_prof.dat (+ derived/LM_Channel_RetauNNN.txt)
                             or the derived table itself.
  same-box mesh DNS (CaNS):  box_<Lx>x<2delta>x<Lz>[_coarse].txt of stats/dns/samebox/, the
                             boxes of chansph's channel scenes (columns y, yp, U+, urms+, vrms+,
                             wrms+, -uv+, each with its standard error).
It returns a dict: yplus, y_delta, re_tau and the QUANTITIES (absent when the set lacks them).
A file that cannot be used raises cli.InputError naming the file and line.
"""
import math
import os
import re

import numpy as np

from .cli import InputError, regular_file

QUANTITIES = ("U+", "u_rms+", "v_rms+", "w_rms+", "-u'v'+")
Y_LO, Y_HI = 20.0, 150.0


def numeric_rows(path, ncol, what):
    """Rows of numbers of a text file, checked: comment (#, %) lines and column-name lines
    before the first row are skipped; every row has at least ncol numbers, as many as the rows
    above, all finite; at least 2 rows. Returns the rows and their line numbers. Raises
    InputError naming the file and line (what: what the file should be, for the message)."""
    regular_file(path, what)
    rows, lines, width = [], [], None
    try:
        with open(path, encoding="utf-8") as f:
            for n, line in enumerate(f, 1):
                if "\0" in line:
                    raise InputError("%s:%d: binary data, not a text table (%s)" % (path, n, what))
                s = line.strip()
                if not s or s[0] in "#%":
                    continue
                try:
                    row = [float(x) for x in re.split(r"[,\s]+", s) if x]
                except ValueError:
                    if rows:
                        raise InputError("%s:%d: not a row of numbers: %.60s" % (path, n, s))
                    continue  # a column-name line before the data
                if len(row) < ncol:
                    raise InputError("%s:%d: %d column(s), %s needs at least %d" %
                                     (path, n, len(row), what, ncol))
                if width is not None and len(row) != width:
                    raise InputError("%s:%d: %d columns, the rows above have %d" %
                                     (path, n, len(row), width))
                bad = [k + 1 for k, x in enumerate(row) if not math.isfinite(x)]
                if bad:
                    raise InputError("%s:%d: non-finite value (NaN or Inf) in column %d" %
                                     (path, n, bad[0]))
                width = len(row)
                rows.append(row)
                lines.append(n)
    except UnicodeDecodeError as e:
        raise InputError("%s: binary data, not a text table (%s): %s" % (path, what, e.reason))
    except OSError as e:
        raise InputError("%s: cannot read %s: %s" % (path, what, e.strerror))
    if len(rows) < 2:
        raise InputError("%s: %s holds %d data row(s) (empty or header only?); at least 2 "
                         "are needed" % (path, what, len(rows)))
    return np.array(rows), lines


def increasing(path, a, col, lines, name):
    """Column col of a (y+ or y/delta) must strictly increase, row by row."""
    for i in range(1, len(a)):
        if not a[i, col] > a[i - 1, col]:
            raise InputError("%s:%d: %s = %.6g is not larger than the previous row's %.6g (rows "
                             "must go from the wall outwards)" %
                             (path, lines[i], name, a[i, col], a[i - 1, col]))
    if not a[-1, col] > 0:
        raise InputError("%s: the last %s is %.6g, not positive" % (path, name, a[-1, col]))


def read_dns(path):
    """A DNS set as a dict: yplus, y_delta, re_tau and the QUANTITIES (None if absent)."""
    base = os.path.basename(path)
    d = os.path.dirname(path)
    out = {"name": base, "label": base}
    m = re.match(r"chan(\d+)\.(means|reystress)$", base)
    if m:  # Moser, Kim & Mansour 1999
        means = os.path.join(d, "chan%s.means" % m.group(1))
        rey = os.path.join(d, "chan%s.reystress" % m.group(1))
        a, lines = numeric_rows(means, 3, "a mean profile (y/delta, y+, U+)")
        increasing(means, a, 0, lines, "y/delta")
        increasing(means, a, 1, lines, "y+")
        out.update(yplus=a[:, 1], y_delta=a[:, 0], re_tau=a[-1, 1] / a[-1, 0])
        out["U+"] = a[:, 2]
        out["source"] = "Moser, Kim & Mansour (1999), %s" % os.path.basename(means)
        if os.path.exists(rey):
            r, _ = numeric_rows(rey, 6, "a Reynolds-stress table (y/delta, y+, uu, vv, ww, uv)")
            if r.shape[0] != a.shape[0] or not np.allclose(r[:, 1], out["yplus"]):
                raise InputError("%s and %s have different y+ points" % (means, rey))
            out["u_rms+"], out["v_rms+"], out["w_rms+"] = (np.sqrt(np.abs(r[:, k])) for k in (2, 3, 4))
            out["-u'v'+"] = -r[:, 5]
            out["source"] += " + " + os.path.basename(rey)
        return out
    if re.match(r"box_[0-9.]+x[0-9.]+x[0-9.]+(_coarse)?\.txt$", base):  # same-box CaNS DNS
        return read_samebox(path, out)
    m = re.match(r"LM_Channel_(\d+)_mean_prof\.dat$", base)
    derived = None
    if m:  # Lee & Moser 2015, mean profile
        a, lines = numeric_rows(path, 3, "a mean profile (y/delta, y+, U+)")
        increasing(path, a, 0, lines, "y/delta")
        increasing(path, a, 1, lines, "y+")
        out.update(yplus=a[:, 1], y_delta=a[:, 0], re_tau=a[-1, 1] / a[-1, 0], source=
                   "Lee & Moser (2015), %s" % base)
        out["U+"] = a[:, 2]
        cand = os.path.join(d, "derived", "LM_Channel_Retau%d.txt" % int(m.group(1)))
        derived = cand if os.path.exists(cand) else None
    elif re.match(r"LM_Channel_Retau(\d+)\.txt$", base):
        derived = path
    if derived:
        names = ("y+", "u_1", "uu_11", "uu_22", "uu_33", "uu_12")
        a, lines = numeric_rows(derived, len(names), "a Lee & Moser derived table")
        try:
            with open(derived, encoding="utf-8") as f:
                header = [h.strip() for h in f.readline().split(",")]
        except (OSError, UnicodeDecodeError) as e:
            raise InputError("%s: cannot read the header line: %s" % (derived, e))
        col = {h: i for i, h in enumerate(header)}
        missing = [h for h in names if h not in col or col[h] >= a.shape[1]]
        if missing:
            raise InputError("%s: the header line names no column %s" % (derived, missing[0]))
        increasing(derived, a, col["y+"], lines, "y+")
        yp = a[:, col["y+"]]
        if "yplus" not in out:
            out.update(yplus=yp, re_tau=yp[-1], y_delta=yp / yp[-1], source="Lee & Moser (2015)")
            out["U+"] = a[:, col["u_1"]]

        def on_grid(v):
            return np.interp(out["yplus"], yp, v)
        out["u_rms+"] = on_grid(np.sqrt(np.abs(a[:, col["uu_11"]])))
        out["v_rms+"] = on_grid(np.sqrt(np.abs(a[:, col["uu_22"]])))
        out["w_rms+"] = on_grid(np.sqrt(np.abs(a[:, col["uu_33"]])))
        out["-u'v'+"] = on_grid(-a[:, col["uu_12"]])
        out["source"] += " + derived/" + os.path.basename(derived)
        return out
    if m:
        return out
    if not os.path.exists(path):
        raise InputError("%s: no such file" % path)
    raise InputError("%s: not a DNS file of a known set: the name must be chanNNN.means or "
                     "chanNNN.reystress (Moser, Kim & Mansour 1999), LM_Channel_NNNN_mean_prof.dat "
                     "or LM_Channel_RetauNNN.txt (Lee & Moser 2015) or box_LXx2xLZ.txt (same-box CaNS, "
                     "stats/dns/samebox)" % path)


def read_samebox(path, out):
    """A same-box CaNS table (stats/dns/samebox/README.md): 12 columns, y/delta, y+, then U+,
    u_rms+, v_rms+, w_rms+, -u'v'+ each followed by its standard error."""
    a, lines = numeric_rows(path, 12, "a same-box DNS table (y, yp, U+, U+_se, ... -uv+_se)")
    increasing(path, a, 0, lines, "y/delta")
    increasing(path, a, 1, lines, "y+")
    out.update(yplus=a[:, 1], y_delta=a[:, 0], re_tau=a[-1, 1] / a[-1, 0],
               source="same-box mesh DNS (CaNS), %s" % os.path.basename(path))
    for k, q in enumerate(QUANTITIES):
        out[q] = a[:, 2 + 2 * k]
        out[q + "_se"] = a[:, 3 + 2 * k]
    return out


def through_bins(dns, lo, hi, at, n=400):
    """The DNS as a particle-binned profile sees it (chansph compare --binned). A bin's
    estimate averages its particles, which spread over the bin, so its mean velocity is the
    bin average of U+ and its u'u' the bin average of <u'u'> plus the spread of the mean
    velocity over the bin, var(U+) (the mean shear broadens it: (dU+/dy+)^2 w+^2 / 12 for a
    bin of width w+ in a linear profile); v, w and u'v' gain nothing (V = 0). The particles are
    taken as uniform over the widest interval inside the bin [lo, hi] centred on their mean
    position `at` (the wall bin's particles keep off the wall). lo, hi, at: arrays in y+.
    Returns {quantity: values at the bins} for the QUANTITIES the set has."""
    half = np.maximum(np.minimum(at - lo, hi - at), 0.0)
    t = (np.arange(n) + 0.5) / n * 2.0 - 1.0  # midpoint rule over [-1, 1]
    y = at[:, None] + half[:, None] * t[None, :]

    def over(v):
        return np.interp(y, dns["yplus"], v)
    out = {}
    if dns.get("U+") is not None:
        u = over(dns["U+"])
        out["U+"] = u.mean(axis=1)
        spread = u.var(axis=1)
    for q in ("u_rms+", "v_rms+", "w_rms+"):
        if dns.get(q) is not None:
            s2 = (over(dns[q]) ** 2).mean(axis=1)
            out[q] = np.sqrt(s2 + (spread if q == "u_rms+" and "U+" in out else 0.0))
    if dns.get("-u'v'+") is not None:
        out["-u'v'+"] = over(dns["-u'v'+"]).mean(axis=1)
    return out


def rel_l2(prof, dns, q):
    """Relative L2 error rms(prof - DNS) / rms(DNS) of quantity q over the bins of profile prof
    inside the DNS's y+ range (NaN where there are none)."""
    yp = prof["yplus"]
    inside = (yp >= dns["yplus"][0]) & (yp <= dns["yplus"][-1]) & np.isfinite(prof[q])
    if not inside.any() or dns.get(q) is None:
        return math.nan
    ref = np.interp(yp[inside], dns["yplus"], dns[q])
    return math.sqrt(np.mean((prof[q][inside] - ref) ** 2)) / math.sqrt(np.mean(ref**2))


def range_deviation(prof, dns, q):
    """Relative deviations of profile q from the DNS at the bins in Y_LO < y+ < Y_HI."""
    yp, v = prof["yplus"], prof[q]
    m = np.isfinite(v) & np.isfinite(yp) & (yp > Y_LO) & (yp < Y_HI)
    if not m.any():
        raise InputError(f"no bins in {Y_LO} < y+ < {Y_HI}")
    return v[m] / np.interp(yp[m], dns["yplus"], dns[q]) - 1.0


def deviation(prof, dns, q, kind):
    """Signed relative deviation of profile q from the DNS: the peak's, or the largest in size
    over Y_LO < y+ < Y_HI."""
    if kind == "peak":
        return np.nanmax(prof[q]) / dns[q].max() - 1.0
    rel = range_deviation(prof, dns, q)
    return rel[np.argmax(np.abs(rel))]
