"""Write solver/dns_lm180.h: the Lee & Moser (2015) Re_tau = 182.088 channel profiles
U+, u'u'+, v'v'+, w'w'+, u'v'+ against y+ (all 96 rows of the shipped file, wall to centre
line) as a C table for the synthetic-eddy start-up (init.profile = synthetic, solver/init.c).

usage (from the repository root; clang-format lays out the table as tests/format_check.sh
wants):
  stats/python/chansph-stats dns_c_table \
      stats/dns/lee_moser2015/derived/LM_Channel_Retau180.txt \
      > solver/dns_lm180.h && clang-format -i solver/dns_lm180.h
"""
from . import cli
from .cli import InputError
from .dns import numeric_rows

NAMES = ["y+", "u_1", "uu_11", "uu_22", "uu_33", "uu_12"]


def read_table(path):
    """Column index by name (the header line) and the rows of a Lee & Moser derived table."""
    rows, _ = numeric_rows(path, len(NAMES), "a Lee & Moser derived table")
    with open(path, encoding="utf-8") as f:
        head = [c.strip() for c in f.readline().split(",")]
    col = {name.lower() if name.lower() == "y+" else name: i for i, name in enumerate(head)}
    missing = [n for n in NAMES if n not in col or col[n] >= rows.shape[1]]
    if missing:
        raise InputError(f"{path}: the header line names no column {missing[0]}")
    return col, rows


def main(argv, prog):
    p = cli.parser(prog, __doc__, raw=True)
    p.add_argument("table", help="derived/LM_Channel_Retau180.txt of stats/dns/lee_moser2015")
    path = p.parse_args(argv).table
    col, rows = read_table(path)
    print(f"""/* Generated from
 *   {path}
 * (Lee & Moser 2015, J. Fluid Mech. 774, 395-415; Re_tau = 182.088; stats/dns/README.md)
 * by the command in stats/python/chansph_stats/dns_c_table.py; do not edit. Columns: y+,
 * U+, u'u'+, v'v'+, w'w'+, u'v'+ (wall units), all rows of the file, wall to centre line. */""")
    print("#ifndef CHANSPH_DNS_LM180_H")
    print("#define CHANSPH_DNS_LM180_H")
    print(f"enum {{ DNS_LM180_N = {len(rows)} }};")
    print("static const double dns_lm180_re_tau = 182.088;")
    print("static const double dns_lm180[DNS_LM180_N][6] = {")
    for r in rows:
        print("    {" + ", ".join(f"{r[col[n]]:.9e}" for n in NAMES) + "},")
    print("};")
    print("#endif")
