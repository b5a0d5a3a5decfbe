"""Particle snapshots: DIR/snapshots/particles.xdmf is well-formed XDMF whose every DataItem
names an existing dataset of the right shape, times increase, and a snapshot of the last step
equals particles.nc bit for bit. usage: snapshot_check.py RUN_DIR"""
import os
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "stats"))
from chansph_nc import read_particles  # noqa: E402

run = sys.argv[1]
sdir = os.path.join(run, "snapshots")
grids = ET.parse(os.path.join(sdir, "particles.xdmf")).getroot().find("Domain/Grid")
ok, times = True, []
for g in grids.findall("Grid"):
    times.append(float(g.find("Time").get("Value")))
    for item in g.iter("DataItem"):
        fname, ds = item.text.split(":")
        dims = tuple(int(d) for d in item.get("Dimensions").split())
        with h5py.File(os.path.join(sdir, fname), "r") as f:
            if f[ds].shape != dims:
                print(f"{fname}:{ds}: shape {f[ds].shape}, XDMF says {dims}")
                ok = False
print(f"{len(times)} snapshots at t = {times}")
ok &= len(times) > 0 and all(a < b for a, b in zip(times, times[1:]))
p = read_particles(os.path.join(run, "particles.nc"))
last = sorted(n for n in os.listdir(sdir) if n.startswith("snap_") and n.endswith(".h5"))[-1]
with h5py.File(os.path.join(sdir, last), "r") as f:
    if int(f.attrs["step"]) == int(p["attrs"]["step"]):
        pos = f["position"][:]
        same = all(np.array_equal(pos[:, k], p[c]) for k, c in enumerate("xyz"))
        same &= np.array_equal(f["pressure"][:], p["p"]) and np.array_equal(f["id"][:], p["id"])
        print(f"{last}: {'identical to' if same else 'DIFFERENT from'} particles.nc")
        ok &= same
print("PASS" if ok else "FAIL")
sys.exit(0 if ok else 1)
