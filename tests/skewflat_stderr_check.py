"""Issue 25: the root group's standard errors of the skewness and flatness profiles
(u_skewness_stderr ... w_flatness_stderr, batch means over the complete windows, stats/euler.c)
equal those chansph-stats skewflat_compare computes from the window records of the same file
(stats/python/chansph_stats/skewflat_compare.py, batches()), to rounding.
usage: skewflat_stderr_check.py STATS.nc"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "stats",
                                "python"))
from chansph_stats import skewflat_compare  # noqa: E402
from chansph_stats.ncfile import open_nc, values  # noqa: E402


def main(path):
    b = skewflat_compare.batches(skewflat_compare.read_run(path, "force"))
    bad, finite = [], 0
    with open_nc(path) as nc:
        for c in "uvw":
            se, k = b[c][1], b[c][2]
            for q, what in enumerate(("skewness", "flatness")):
                name = "%s_%s_stderr" % (c, what)
                x, y = values(nc.variables[name]), np.asarray(se[q], dtype=float)
                same_nan = np.array_equal(np.isfinite(x), np.isfinite(y))
                ok = np.isfinite(x) & np.isfinite(y)
                finite += int(ok.sum())
                close = np.allclose(x[ok], y[ok], rtol=1e-12, atol=1e-14)
                if not (same_nan and close):
                    bad.append(name)
    good = not bad and finite > 0
    print("%s: skewness and flatness standard errors of %s (%d windows, %d finite values) %s "
          "the batch means of skewflat_compare" %
          ("PASS" if good else "FAIL", path, k, finite, "equal" if not bad else
           "DIFFER from (%s)" % ", ".join(bad)))
    return 0 if good else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
