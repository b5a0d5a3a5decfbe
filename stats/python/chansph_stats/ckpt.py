"""Reader for chansph checkpoints (docs/checkpoint-format.md), with h5py.

Usage (with stats/python on sys.path):
    from chansph_stats.ckpt import read_checkpoint
    c = read_checkpoint("runs/p2d/checkpoints/ckpt_0000000770.h5")
    c["step"], c["time"], c["scene"], c["particles"]["x"], c["data"]["stats/profile/sum_u"]
Particle arrays are returned sorted by particle id; "fluid" selects the fluid particles.
A file that is missing, not HDF5 or not a complete chansph checkpoint raises cli.InputError.
Needs python3-h5py and python3-numpy (Debian packages). HDF5 verifies the Fletcher32 checksum of
every dataset while reading.
"""
import h5py
import numpy as np

from .cli import InputError, regular_file

FORMAT = "chansph-checkpoint"
MAJOR = 1


def _text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def open_h5(path):
    """h5py.File of path (read-only); InputError if it is missing or not HDF5."""
    regular_file(path)
    try:
        return h5py.File(path, "r")
    except OSError as e:
        raise InputError("%s: cannot open as HDF5 (%s)" % (path, e))


def read_checkpoint(path):
    """Every dataset of a checkpoint; particles sorted by id. Refuses other formats."""
    with open_h5(path) as f:
        if _text(f.attrs.get("format", b"")) != FORMAT:
            raise InputError(f"{path}: not a chansph checkpoint")
        major = int(f.attrs["format_version_major"])
        if major > MAJOR:
            raise InputError(f"{path}: checkpoint format {major}.x is newer than this reader")
        if int(f.attrs.get("complete", 0)) != 1:
            raise InputError(f"{path}: incomplete checkpoint")
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
