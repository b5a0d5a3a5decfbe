#!/usr/bin/python3
"""`chansph compare` runs this file (compare_main in stats/extract.c runs CHANSPH_STATS_DIR/
compare.py): the compare tool of the chansph_stats package beside it."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.realpath(__file__)))
from chansph_stats import cli, compare  # noqa: E402

sys.exit(cli.run(compare.main, sys.argv[1:]))
