"""Summarise chansph checkpoints: format, step, time, fluid particles, datasets.

usage: chansph-stats ckpt CKPT.h5 ...
"""
from . import cli
from .ckpt import read_checkpoint


def main(argv, prog):
    p = cli.parser(prog, __doc__)
    p.add_argument("checkpoints", nargs="+", metavar="CKPT.h5")
    for path in p.parse_args(argv).checkpoints:
        c = read_checkpoint(path)
        print(f"{path}: format {c['version'][0]}.{c['version'][1]}, step {c['step']}, "
              f"t = {c['time']:.9g} s, {int(c['fluid'].sum())} fluid particles, "
              f"{len(c['data'])} datasets")
