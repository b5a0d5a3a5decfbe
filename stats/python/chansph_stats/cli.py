"""The conventions every chansph Python tool follows on the command line.

One error style, as the C side's (solver/base/error.h, `error_input`): a file or argument the
tool cannot use is reported on stderr as one line, "error: FILE-OR-ARGUMENT: what is wrong",
with exit status 1 and no traceback; a usage error prints that line and then the usage.
A failed check (tests) is not an input error: it prints FAIL and exits 1 on its own.
"""
import argparse
import math
import os
import sys


class InputError(Exception):
    """A file or argument a tool cannot use: reported as "error: ..." with exit 1."""


class Parser(argparse.ArgumentParser):
    """argparse with chansph's usage errors: "error: ..." first, then the usage, exit 1."""

    def error(self, message):
        print("error: %s" % message, file=sys.stderr)
        self.print_usage(sys.stderr)
        sys.exit(1)


def parser(prog, doc, **kwargs):
    """A Parser for tool prog ("chansph-stats windows") whose description is the docstring doc
    (its first line unless raw=True, then the whole of it, laid out as written)."""
    if kwargs.pop("raw", False):
        return Parser(prog=prog, description=doc, formatter_class=argparse.RawTextHelpFormatter,
                      **kwargs)
    return Parser(prog=prog, description=doc.split("\n")[0], **kwargs)


def run(main, *args):
    """Call main(*args) and turn an input error into the one-line message and exit status 1.
    An OSError that reaches here (a file that cannot be read or written) is one too, named by
    its file. Returns main's return value (an exit status or None)."""
    try:
        return main(*args)
    except InputError as e:
        sys.exit("error: %s" % one_line(str(e)))
    except OSError as e:
        where = "%s: " % e.filename if e.filename else ""
        sys.exit("error: %s%s" % (where, one_line(e.strerror or str(e))))


def regular_file(path, what=""):
    """InputError "PATH: cannot open[ WHAT]: No such file" unless path is a regular file."""
    if not os.path.isfile(path):
        raise InputError("%s: cannot open%s: %s" % (path, " " + what if what else "",
                                                     "No such file" if not os.path.exists(path)
                                                     else "not a regular file"))


def one_line(text):
    """text with its line breaks turned into spaces (a message is one line)."""
    return " ".join(text.split("\n"))


def number(kind=float, low=None, above=False):
    """An argparse type: a finite number of type kind (int or float), at least low (above:
    larger than low) when low is given. The message names the value and the bound."""
    name = "an integer" if kind is int else "a number"

    def convert(text):
        try:
            x = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError("%r is not %s" % (text, name))
        if not math.isfinite(x):
            raise argparse.ArgumentTypeError("%s: must be finite" % text)
        if low is not None and (x <= low if above else x < low):
            raise argparse.ArgumentTypeError("%s: must be %s %g" %
                                             (text, "larger than" if above else "at least", low))
        return x
    convert.__name__ = kind.__name__  # argparse names the type in its messages
    return convert


def run_spec(spec):
    """A series over a time range, LABEL=RUN_DIR[+RUN_DIR...]@T0:T1: (label, dirs, t0, t1), or
    InputError naming the spec."""
    label, _, rest = spec.partition("=")
    dirs, _, span = rest.rpartition("@")
    if not dirs or not span:
        raise InputError(f"{spec}: expected LABEL=RUN_DIR[+RUN_DIR...]@T0:T1")
    try:
        t0, t1 = window(span)
    except argparse.ArgumentTypeError as e:
        raise InputError(f"{spec}: {e}")
    return label, dirs, t0, t1


def window(text):
    """argparse type: a time range T0:T1 (T1 may be inf), T0 <= T1."""
    t0, _, t1 = text.partition(":")
    try:
        a, b = float(t0), float(t1)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text}: expected T0:T1")
    if not a <= b:
        raise argparse.ArgumentTypeError(f"{text}: expected T0:T1 with T0 <= T1")
    return a, b
