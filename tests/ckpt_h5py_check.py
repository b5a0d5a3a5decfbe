"""A checkpoint read with h5py (stats/chansph_ckpt.py) holds the particle state of particles.nc
written at the same step, bit for bit; the scene and the step agree.
usage: ckpt_h5py_check.py RUN_DIR"""
import glob
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "stats"))
import numpy as np  # noqa: E402
from chansph_ckpt import read_checkpoint  # noqa: E402
from chansph_nc import read_particles  # noqa: E402

run = sys.argv[1]
last = sorted(glob.glob(os.path.join(run, "checkpoints", "ckpt_*.h5")))[-1]
c = read_checkpoint(last)
p = read_particles(os.path.join(run, "particles.nc"))
ok = c["step"] == int(p["attrs"]["step"]) and c["data"]["sim/step"] == c["step"]
fluid = {k: v[c["fluid"]] for k, v in c["particles"].items()}
ok &= np.array_equal(fluid["id"], p["id"])
for k in ("x", "y", "z", "u", "v", "w", "rho", "p", "gamma", "mass"):
    same = np.array_equal(fluid[k], p[k])
    ok &= same
    print(f"{k}: {'identical' if same else 'DIFFERENT'}")
ok &= "[domain]" in c["scene"]
print(f"{last}: step {c['step']}, t = {c['time']}, {len(c['data'])} datasets;",
      "PASS" if ok else "FAIL")
sys.exit(0 if ok else 1)
