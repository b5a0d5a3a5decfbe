#!/usr/bin/python3
"""Run the commands of docs/user-guide.md as a user would, and check the output it shows.

The part of the guide between the markers "<!-- guide-test: begin -->" and
"<!-- guide-test: end -->" is run in a fresh folder WORK that looks like the repository root
(jobs/, stats/, tests/, docs/ link to the sources, build/ to the build): each line of a ```sh
block is one command, run with bash in WORK; it must exit 0, or N where the line ends with
"# exit N". A ```text block after a ```sh block is an excerpt of what that block printed: each
of its lines must be one of the printed lines, with every number replaced by # on both sides
(the numbers of a run change; the words, units and layout must not).
usage: user_guide_check.py SOURCE_DIR BUILD_DIR WORK_DIR
"""
import os
import re
import shutil
import subprocess
import sys

NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def norm(line):
    return " ".join(NUMBER.sub("#", line).split())


def blocks(text):
    """The fenced blocks of the tested part: [(kind, [lines])]."""
    try:
        part = text.split("<!-- guide-test: begin -->", 1)[1].split("<!-- guide-test: end -->", 1)[0]
    except IndexError:
        sys.exit("FAIL: docs/user-guide.md: no guide-test markers")
    return [(m.group(1), m.group(2).rstrip("\n").split("\n"))
            for m in re.finditer(r"```(\w+)\n(.*?)```", part, re.S)]


def run_line(line, work):
    m = re.search(r"#\s*exit\s+(\d+)\s*$", line)
    want = int(m.group(1)) if m else 0
    env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "1"))
    p = subprocess.run(["bash", "-c", line], cwd=work, env=env, stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, text=True)
    if p.returncode != want:
        print(p.stdout[-4000:])
        sys.exit("FAIL: `%s` exited %d, the guide says %d" % (line, p.returncode, want))
    return p.stdout


def main(src, build, work):
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    for d in ("jobs", "stats", "tests", "docs"):
        os.symlink(os.path.join(src, d), os.path.join(work, d))
    os.symlink(build, os.path.join(work, "build"))
    with open(os.path.join(src, "docs", "user-guide.md")) as f:
        found = blocks(f.read())
    out, commands, excerpts = "", 0, 0
    for kind, lines in found:
        if kind == "sh":
            out = ""
            for line in lines:
                if line.strip() and not line.lstrip().startswith("#"):
                    print("$ " + line, flush=True)
                    out += run_line(line, work)
                    commands += 1
        elif kind == "text":
            have = {norm(x) for x in out.split("\n")}
            for line in lines:
                if line.strip() and line.strip() != "..." and norm(line) not in have:
                    print(out[-4000:])
                    sys.exit("FAIL: the guide shows a line the command did not print:\n  %s" % line)
                excerpts += 1
    if commands < 10:
        sys.exit("FAIL: only %d commands found in the guide's tested part" % commands)
    print("PASS: %d commands of docs/user-guide.md ran as documented; %d output lines as shown"
          % (commands, excerpts))


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(*(os.path.abspath(a) for a in sys.argv[1:]))
