"""A checkpoint read with h5py (chansph_stats.ckpt) holds the particle state of particles.nc
written at the same step, bit for bit; the scene and the step agree.
usage: ckpt_h5py_check.py RUN_DIR"""
import glob
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../stats/python"))
import numpy as np  # noqa: E402
from chansph_stats import cli  # noqa: E402
from chansph_stats.ckpt import read_checkpoint  # noqa: E402
from chansph_stats.ncfile import need_keys, read_particles  # noqa: E402

PARTICLE_VARS = ("id", "x", "y", "z", "u", "v", "w", "rho", "p", "gamma", "mass")


def main():
    p = cli.parser("ckpt_h5py_check.py", __doc__)
    p.add_argument("run", metavar="RUN_DIR")
    run = p.parse_args().run
    found = sorted(glob.glob(os.path.join(run, "checkpoints", "ckpt_*.h5")))
    if not found:
        raise cli.InputError(f"{run}: no checkpoints/ckpt_*.h5")
    last = found[-1]
    c = read_checkpoint(last)
    path = os.path.join(run, "particles.nc")
    p = read_particles(path)
    need_keys(p, path, PARTICLE_VARS, ("step",), "a chansph particles.nc")
    ok = c["step"] == int(p["attrs"]["step"]) and c["data"]["sim/step"] == c["step"]
    fluid = {k: v[c["fluid"]] for k, v in c["particles"].items()}
    ok &= np.array_equal(fluid["id"], p["id"])
    for k in PARTICLE_VARS[1:]:
        same = np.array_equal(fluid[k], p[k])
        ok &= same
        print(f"{k}: {'identical' if same else 'DIFFERENT'}")
    ok &= "[domain]" in c["scene"]
    print(f"{last}: step {c['step']}, t = {c['time']}, {len(c['data'])} datasets;",
          "PASS" if ok else "FAIL")
    return 0 if ok else 1


sys.exit(cli.run(main))
