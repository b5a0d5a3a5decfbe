#!/usr/bin/python3
"""The Python merge of window records (chansph_stats.merge: error_vs_time,
resolution_extrapolate, window_peaks) against chansph extract: over a sub-range of windows, in wall units of the
range's wall shear stress, both give the same y+, u_rms+, v_rms+ and -u'v'+ (in the lower half, where an unfolded run's profiles are
not mirrored by the Python side).

usage: window_profile_check.py CHANSPH STATS_RUN_DIR T0:T1
"""
import math
import os
import subprocess
import sys

import netCDF4
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../stats/python"))
from chansph_stats.error_vs_time import group_profiles  # noqa: E402
from chansph_stats.merge import window_profile  # noqa: E402


def main():
    chansph, run, span = sys.argv[1], sys.argv[2], sys.argv[3]
    t0, t1 = (float(x) for x in span.split(":"))
    res = subprocess.run([chansph, "extract", os.path.join(run, "stats.nc"), "--units", "wall",
                          "--format", "csv", "--window", span, "--var", "uv,u_rms,v_rms"],
                         capture_output=True, text=True)
    if res.returncode:
        sys.exit(f"FAIL: chansph extract: {res.stderr}")
    lines = [ln for ln in res.stdout.splitlines() if not ln.startswith("#")]
    head = lines[0].split(",")
    data = np.array([[float(x) for x in ln.split(",")] for ln in lines[1:]])
    ext = {h: data[:, i] for i, h in enumerate(head)}
    prof, got = window_profile(run, t0, t1, "wall")
    with netCDF4.Dataset(os.path.join(run, "stats.nc")) as nc:
        lower = ext["y"] < float(nc.delta)
    if lower.sum() < 3 or len(lower) != len(prof["yplus"]):
        sys.exit(f"FAIL: {len(lower)} bins from extract, {len(prof['yplus'])} from Python")
    if abs(got[0] - t0) > 1e-9 or abs(got[1] - t1) > 1e-9:
        sys.exit(f"FAIL: windows taken {got}, asked {t0}-{t1}")
    worst = 0.0
    for ours, theirs in (("yplus", "y_plus"), ("u_rms+", "u_rms"), ("v_rms+", "v_rms"),
                         ("-u'v'+", "uv")):
        a = prof[ours][lower]
        b = (-ext[theirs] if theirs == "uv" else ext[theirs])[lower]
        scale = np.nanmax(np.abs(b))
        if not scale > 0:
            sys.exit(f"FAIL: {theirs} is zero or NaN everywhere")
        err = np.nanmax(np.abs(a - b)) / scale
        print(f"{ours:<8} max |python - extract| / max|extract| = {err:.2e}")
        worst = max(worst, err)
    if worst > 1e-6:  # extract prints 9 significant digits
        sys.exit(f"FAIL: the merges differ by {worst:.2e}")
    print("the Python window merge matches chansph extract")
    # error_vs_time --cumulative T0: its last group is the running average of all the windows
    # from T0 on, which window_profile gives directly (force units, as error_vs_time uses)
    groups = group_profiles(run, 0.2, since=t0)
    full, _ = window_profile(run, t0, math.inf)
    last = groups[-1][2]
    if len(groups) < 2 or abs(groups[-1][0] - t0) > 1e-9 or \
            not np.allclose(last["u_rms+"], full["u_rms+"], rtol=1e-12, equal_nan=True):
        sys.exit("FAIL: the cumulative group is not the running average from T0")
    first = group_profiles(run, 0.2)[-1][2]  # the last group alone differs from it
    if np.allclose(first["u_rms+"], full["u_rms+"], rtol=1e-6, equal_nan=True):
        sys.exit("FAIL: the test cannot tell a group from the running average")
    print(f"error_vs_time --cumulative: {len(groups)} groups, the last = the average from {t0}")


if __name__ == "__main__":
    main()
