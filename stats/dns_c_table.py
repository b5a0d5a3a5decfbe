#!/usr/bin/env python3
"""Write solver/dns_lm180.h: the Lee & Moser (2015) Re_tau = 182.088 channel profiles
U+, u'u'+, v'v'+, w'w'+, u'v'+ against y+ (all 96 rows of the shipped file, wall to centre
line) as a C table for the synthetic-eddy start-up (init.profile = synthetic, solver/init.c).

usage (from the repository root; clang-format lays out the table as tests/format_check.sh
wants):
  python3 stats/dns_c_table.py stats/dns/lee_moser2015/derived/LM_Channel_Retau180.txt \
      > solver/dns_lm180.h && clang-format -i solver/dns_lm180.h
"""
import sys

path = sys.argv[1]
with open(path) as f:
    head = [c.strip() for c in f.readline().split(",")]
    rows = [[float(v) for v in line.split()] for line in f if line.strip()]
col = {name.lower() if name.lower() == "y+" else name: i for i, name in enumerate(head)}
names = ["y+", "u_1", "uu_11", "uu_22", "uu_33", "uu_12"]
print("/* Generated from")
print(f" *   {path}")
print(" * (Lee & Moser 2015, J. Fluid Mech. 774, 395-415; Re_tau = 182.088; stats/dns/README.md)")
print(" * by the command in stats/dns_c_table.py; do not edit. Columns: y+, U+, u'u'+, v'v'+,")
print(" * w'w'+, u'v'+ (wall units), all rows of the file, wall to centre line. */")
print("#ifndef CHANSPH_DNS_LM180_H")
print("#define CHANSPH_DNS_LM180_H")
print(f"enum {{ DNS_LM180_N = {len(rows)} }};")
print("static const double dns_lm180_re_tau = 182.088;")
print("static const double dns_lm180[DNS_LM180_N][6] = {")
for r in rows:
    print("    {" + ", ".join(f"{r[col[n]]:.9e}" for n in names) + "},")
print("};")
print("#endif")
