"""chansph_stats: the analysis tools of chansph's outputs, in one package (docs/architecture.md,
"Analysis scripts").

Run a tool with the wrapper (from anywhere):
    stats/python/chansph-stats TOOL [ARGS...]        (stats/python/chansph-stats --help: the list)
or with the package on the path:
    PYTHONPATH=stats/python /usr/bin/python3 -m chansph_stats TOOL [ARGS...]
`chansph compare` runs the compare tool (stats/python/compare.py).

Shared modules (import them with stats/python on sys.path):
    cli      the command-line conventions: one-line "error: ..." messages, exit 1, no traceback
    ncfile   the one reader of stats.nc and particles.nc (read_stats, read_particles, read_windows)
    ckpt     the reader of checkpoints (read_checkpoint)
    dns      the DNS data sets of stats/dns/ (read_dns) and deviations from them
    merge    window records merged into profiles in wall units
Needs python3-numpy, python3-netcdf4, python3-h5py, python3-matplotlib (Debian packages).
"""
