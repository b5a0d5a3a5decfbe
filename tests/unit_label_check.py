#!/usr/bin/python3
"""The ctest label `unit` takes seconds (issue 26, point 16; README: tests/run.sh -L unit).
A test labelled unit may not: run a SLURM chain, ParaView, a restart equivalence, signal or
kill scenario (names matching SLOW_NAMES), require a fixture other than stats_small (ctest
-L unit runs a required fixture's setup test too, e.g. restart_bitwise_* for ckpt_*), or be
one of the tests measured above ~5 s (SLOW, 2 cores, 2026-12-02).
usage: unit_label_check.py BUILD_DIR"""
import json
import re
import subprocess
import sys

SLOW_NAMES = r"slurm|paraview|bitwise|restart_signals|restart_kill|batch_chain|run_dir_replaced"
SLOW = {"run_summaries": 15, "python_input_errors": 41, "converge_stop": 13,
        "compare_extract_inputs": 8, "q_criterion_poiseuille": 7,
        "q_criterion_threads_bitwise": 8, "compare_u_tau": 5, "compare_plots": 5,
        "final_snapshot": 6}
FAST_FIXTURES = {"stats_small"}


def main():
    out = subprocess.run(["ctest", "--show-only=json-v1"], cwd=sys.argv[1], check=True,
                         capture_output=True, text=True).stdout
    problems, n = [], 0
    for t in json.loads(out)["tests"]:
        props = {p["name"]: p["value"] for p in t.get("properties", [])}
        if "unit" not in props.get("LABELS", []):
            continue
        n += 1
        name = t["name"]
        if re.search(SLOW_NAMES, name):
            problems.append("%s: a slow kind of test (%s) labelled unit" % (name, SLOW_NAMES))
        if name in SLOW:
            problems.append("%s: measured %d s, labelled unit" % (name, SLOW[name]))
        extra = set(props.get("FIXTURES_REQUIRED", [])) - FAST_FIXTURES
        if extra:
            problems.append("%s: labelled unit but needs fixture %s (its setup runs too)" %
                            (name, ", ".join(sorted(extra))))
    for p in problems:
        print("FAIL: " + p)
    print("%d unit tests, %d problems" % (n, len(problems)))
    return 1 if problems else 0


sys.exit(main())
