"""Reader for chansph checkpoints (docs/checkpoint-format.md), with h5py.

Usage:
    from chansph_ckpt import read_checkpoint
    c = read_checkpoint("runs/p2d/checkpoints/ckpt_0000000770.h5")
    c["step"], c["time"], c["scene"], c["particles"]["x"], c["data"]["stats/profile/sum_u"]
Particle arrays are returned sorted by particle id; "fluid" selects the fluid particles.
Needs python3-h5py and python3-numpy (Debian packages). HDF5 verifies the Fletcher32 checksum of
every dataset while reading.
"""
import h5py
import numpy as np

FORMAT = "chansph-checkpoint"
MAJOR = 1


def _text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def read_checkpoint(path):
    """Every dataset of a checkpoint; particles sorted by id. Refuses other formats."""
    with h5py.File(path, "r") as f:
        if _text(f.attrs.get("format", b"")) != FORMAT:
            raise ValueError(f"{path}: not a chansph checkpoint")
        major = int(f.attrs["format_version_major"])
        if major > MAJOR:
            raise ValueError(f"{path}: checkpoint format {major}.x is newer than this reader")
        if int(f.attrs.get("complete", 0)) != 1:
            raise ValueError(f"{path}: incomplete checkpoint")
        data = {}

        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                v = obj[()]
                data[name] = v[0] if obj.attrs.get("scalar", 0) == 1 else v
        f.visititems(visit)
        out = {"step": int(f.attrs["step"]), "time": float(f.attrs["time"]),
               "version": (major, int(f.attrs["format_version_minor"])),
               "scene": _text(data.pop("scene")), "data": data}
    order = np.argsort(data["particles/id"], kind="stable")
    out["particles"] = {k.split("/", 1)[1]: v[order] for k, v in data.items()
                        if k.startswith("particles/")}
    out["fluid"] = out["particles"]["kind"] == 0
    return out


if __name__ == "__main__":
    import sys
    for p in sys.argv[1:]:
        c = read_checkpoint(p)
        print(f"{p}: format {c['version'][0]}.{c['version'][1]}, step {c['step']}, "
              f"t = {c['time']:.9g} s, {int(c['fluid'].sum())} fluid particles, "
              f"{len(c['data'])} datasets")
