#!/usr/bin/python3
"""Check the links of README.md and docs/**/*.md, and that no page cites issue numbers.

Links: every Markdown link or image [text](target) outside code, relative targets only (http
links are not followed: the test runs offline): the file or folder must exist, and a #anchor
must be a heading of the target page (GitHub's rule: lower case, punctuation but - and _
dropped, spaces to -). Issue numbers: "issue 24" (any case) names the work, not the subject,
and means nothing to a reader; no page may contain one.
usage: doc_links_check.py SOURCE_DIR
"""
import glob
import os
import re
import sys

LINK = re.compile(r"!?\[([^\]]*)\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
ISSUE = re.compile(r"\bissues?\s+#?[0-9]", re.I)


def slug(heading):
    s = heading.strip().lower()
    s = re.sub(r"[^\w\- ]", "", s)
    return s.replace(" ", "-")


def anchors(path, cache={}):
    if path not in cache:
        with open(path) as f:
            text = re.sub(r"```.*?```", "", f.read(), flags=re.S)
        seen, out = {}, set()
        for m in re.finditer(r"^#{1,6}\s+(.*?)\s*#*\s*$", text, re.M):
            s = slug(m.group(1))
            n = seen.get(s, 0)
            out.add(s if n == 0 else "%s-%d" % (s, n))
            seen[s] = n + 1
        cache[path] = out
    return cache[path]


def check_page(page, src):
    bad = []
    with open(page) as f:
        text = f.read()
    prose = re.sub(r"```.*?```", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S)
    prose = re.sub(r"`[^`\n]*`", "``", prose)
    rel = os.path.relpath(page, src)
    for n, line in enumerate(text.split("\n"), 1):
        if ISSUE.search(line):
            bad.append("%s:%d: cites an issue number: %s" % (rel, n, line.strip()[:100]))
    for n, line in enumerate(prose.split("\n"), 1):
        for m in LINK.finditer(line):
            target = m.group(2)
            if re.match(r"[a-z]+:", target):
                continue
            path, _, anchor = target.partition("#")
            dest = os.path.normpath(os.path.join(os.path.dirname(page), path)) if path else page
            if not os.path.exists(dest):
                bad.append("%s:%d: link to a missing file: %s" % (rel, n, target))
            elif anchor and dest.endswith(".md") and anchor not in anchors(dest):
                bad.append("%s:%d: no heading #%s in %s" % (rel, n, anchor,
                                                           os.path.relpath(dest, src)))
    return bad, len(LINK.findall(prose))


def main(src):
    pages = [os.path.join(src, "README.md")] + sorted(
        glob.glob(os.path.join(src, "docs", "**", "*.md"), recursive=True))
    bad, links = [], 0
    for p in pages:
        b, n = check_page(p, src)
        bad += b
        links += n
    for b in bad:
        print(b)
    if bad:
        print("FAIL: %d problems in %d pages" % (len(bad), len(pages)))
        return 1
    print("PASS: %d links in %d pages resolve; no page cites an issue number" % (links, len(pages)))
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    sys.exit(main(os.path.abspath(sys.argv[1])))
