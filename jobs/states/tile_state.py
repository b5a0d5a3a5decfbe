#!/usr/bin/python3
"""Stack two shipped states of the same channel side by side in z: a start for a box of twice
the span (the converged run in lz = 2 x 0.7 delta, where the minimal unit's bursting
is weaker).

usage: python3 jobs/states/tile_state.py A.nc B.nc OUT.nc [--perturb EPS] [--seed N]

A and B are states (jobs/states/reduce_state.py, or particles.nc) of the same scene domain and
particle count; OUT holds A at 0 <= z < lz and B shifted by lz, ids of B offset by A's count,
and the scene attribute with lz doubled, so that init.from of a scene with that lz takes the
particles as they are. With B = A the field is periodic in lz and has no seams; a copy is a
symmetry the dynamics keep up to round-off, so --perturb adds Gaussian noise of standard
deviation EPS [m/s] to the copy's velocities (it decorrelates within about a turnover). Two
different states (B != A) join unrelated fields at z = 0 and lz: the particle layers there do
not match, and in the dr+ = 6 channel that sent a particle through the wall at step 169.
"""
import os
import re
import sys

import netCDF4
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../../stats/python"))
from chansph_stats import cli  # noqa: E402
from chansph_stats.ncfile import need, open_nc  # noqa: E402

STATE_VARS = ("id", "x", "y", "z", "u", "v", "w", "rho", "mass")


def domain_lz(scene, path):
    """The [domain] lz of a scene text and the span of the text holding its value."""
    sec = re.search(r"^\[domain\][^\[]*", scene, re.M)
    m = sec and re.search(r"^\s*lz\s*=\s*([0-9.eE+-]+)", sec.group(0), re.M)
    if not m:
        raise cli.InputError(f"{path}: its scene attribute has no [domain] lz")
    return float(m.group(1)), (sec.start() + m.start(1), sec.start() + m.end(1))


def main():
    p = cli.parser("tile_state.py", __doc__)
    p.add_argument("a", metavar="A.nc")
    p.add_argument("b", metavar="B.nc")
    p.add_argument("out", metavar="OUT.nc")
    p.add_argument("--perturb", type=cli.number(float, 0), default=0.0, metavar="EPS")
    p.add_argument("--seed", type=int, default=1)
    a = p.parse_args()
    with open_nc(a.a) as A, open_nc(a.b) as B:
        va = {n: np.asarray(need(A, n, a.a, "a chansph state")[:]) for n in STATE_VARS}
        vb = {n: np.asarray(need(B, n, a.b, "a chansph state")[:]) for n in STATE_VARS}
        for f, d in ((a.a, A), (a.b, B)):
            if "scene" not in d.ncattrs():
                raise cli.InputError(f"{f}: no scene attribute (not a chansph state)")
        lz, span = domain_lz(A.scene, a.a)
        lzb, _ = domain_lz(B.scene, a.b)
        if lzb != lz or len(va["id"]) != len(vb["id"]):
            raise cli.InputError(f"{a.b}: lz {lzb} and {len(vb['id'])} particles, not those of "
                                 f"{a.a} ({lz}, {len(va['id'])})")
        scene = A.scene[:span[0]] + repr(2 * lz) + A.scene[span[1]:]
        atts = {k: A.getncattr(k) for k in A.ncattrs()}
        var_atts = {n: {k: A[n].getncattr(k) for k in A[n].ncattrs() if k != "_FillValue"}
                    for n in STATE_VARS}
        kinds = {n: A[n].dtype for n in STATE_VARS}
    n = len(va["id"])
    out = {k: np.concatenate([va[k], vb[k]]) for k in STATE_VARS}
    out["z"][n:] += lz
    out["id"][n:] += n
    rng = np.random.default_rng(a.seed)
    for k in ("u", "v", "w"):
        if a.perturb > 0:
            out[k][n:] += rng.normal(0.0, a.perturb, n).astype(out[k].dtype)
    atts["scene"] = scene
    try:
        dst = netCDF4.Dataset(a.out, "w", format="NETCDF4")
    except OSError as e:
        raise cli.InputError(f"{a.out}: cannot create: {e.strerror or e}")
    with dst:
        dst.setncatts(atts)
        dst.createDimension("particle", 2 * n)
        for k in STATE_VARS:
            v = dst.createVariable(k, kinds[k], ("particle",), zlib=True, complevel=9,
                                   shuffle=True)
            v.setncatts(var_atts[k])
            v[:] = out[k]
    print(f"{a.out}: {2 * n} particles, lz {2 * lz}")


sys.exit(cli.run(main))
