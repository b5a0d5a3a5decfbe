"""The PASS/FAIL lines of the Python checks in tests/, and their exit status.

    from passfail import check, finish
    check(value == expected, "what was checked")   # prints PASS: ... or FAIL: ...
    finish()                                       # exit 1 if any check failed, else 0
"""
import sys

FAILS = []


def check(ok, what):
    """Print PASS or FAIL with what; remember a failure. Returns ok."""
    print("%s: %s" % ("PASS" if ok else "FAIL", what))
    if not ok:
        FAILS.append(what)
    return ok


def finish(part=None):
    """Exit 1 if any check failed, else 0; with part, a summary line first."""
    if part is not None:
        print("%s: %s" % (part, "FAIL (%d)" % len(FAILS) if FAILS else "PASS"))
    sys.exit(1 if FAILS else 0)
