#!/usr/bin/python3
"""The peak position of a binned profile (chansph_stats.merge.peak_position, the peak y+ of
chansph-stats ab_score): the vertex of a parabola sampled on unevenly spaced bins is recovered
to round-off wherever the maximum bin lies inside; a profile rising to its last bin, or
falling from its first, gives that bin; NaN bins are skipped; a flat top gives a point on it; on a Gaussian bump sampled every
6 wall units the vertex is within 1 wall unit of the true peak where the largest bin alone is
up to 3 off.

usage: peak_position_check.py ROOT
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(sys.argv[1], "stats", "python"))
from chansph_stats.merge import peak_position  # noqa: E402
from passfail import check, finish  # noqa: E402

y = np.array([1.0, 2.5, 5.0, 9.0, 14.0, 21.0, 30.0, 42.0])
for top in (4.0, 13.3, 27.0):
    f = 3.0 - 0.01 * (y - top) ** 2
    got = peak_position(y, f)
    check(abs(got - top) < 1e-9 * top, f"parabola with its vertex at {top}: {got}")
check(peak_position(y, y) == 42.0, "a rising profile: its last bin")
check(peak_position(y, -y) == 1.0, "a falling profile: its first bin")
f = 3.0 - 0.01 * (y - 13.3) ** 2
f[[0, 6]] = np.nan
check(abs(peak_position(y, f) - 13.3) < 1e-9, "NaN bins skipped")
check(np.isnan(peak_position(y, np.full(y.size, np.nan))), "an all-NaN profile: NaN")
flat = np.array([0.0, 1.0, 1.0, 1.0, 0.0])
got = peak_position(np.arange(5.0), flat)
check(1.0 <= got <= 3.0, f"a flat top over bins 1-3: inside it ({got})")
yb = np.arange(3.0, 150.0, 6.0)
worst_bin = worst_fit = 0.0
for top in np.linspace(10.0, 40.0, 31):
    g = np.exp(-0.5 * ((yb - top) / 12.0) ** 2)
    worst_fit = max(worst_fit, abs(peak_position(yb, g) - top))
    worst_bin = max(worst_bin, abs(yb[np.argmax(g)] - top))
check(worst_fit < 1.0 and worst_bin > 2.5,
      f"Gaussian bump on 6-wide bins: vertex off by {worst_fit:.2f}, largest bin by {worst_bin:.2f}")
finish()
