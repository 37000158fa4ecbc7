#!/usr/bin/env python3
"""The README and docs/ are for a user who has only the repository: this check fails on any line of
README.md, docs/**/*.md or the Python package's modules (python/pixelgym/*.py, whose docstrings
help() shows) that points outside it, uses an env id for which a newer version is
registered, or links to a file or heading that is not there.

Rules (each names the page, the line and what it found):

- shared folder: `../shared`, `shared/design`, `shared/peers` (the machine's shared folder is not
  part of the repository).
- machine path: an absolute path under /work/, /root/, /home/ or /Users/ anywhere (where a page was
  written or measured, not something a user has); /tmp/ outside fenced code blocks (a command a
  user runs may write to /tmp, prose that names a /tmp file is a lab note). System paths a user's
  machine has too (/usr/bin/python3, /usr/lib/...) are allowed.
- issue number: `issue 12`, `issues 12`, `issue #12`, `issues/12`, `PR 12`, and `#12` outside code
  (`#12` in a code span or block is code, e.g. an HTML entity).
- lab note: "this session", "last session", "previous session", "earlier session", "this VM",
  "this 2-core VM" (who measured when belongs to a record in docs/experiments/ or bench/), and
  outside docs/experiments/ a date such as 2026-11-26 that is not part of a path (a record's file
  name may hold its date).
- out-of-date id: an id NAME-vN of a registered env when NAME-vM with M > N is registered (what
  `pixelgym list` prints). Allowed between `<!-- older ids: REASON -->` and `<!-- /older ids -->`
  (a table of every registered id, a page that explains versions, a measurement that names the id
  it measured: the REASON says which), in the README's headline figures (written by
  bench/report.py between its markers from the ids measured), and in docs/experiments/ (a record
  names the id it ran).
- broken link: a relative link or image whose file does not exist, or whose #anchor is no heading
  of the page it names.

Usage: docs_check.py SOURCE_DIR PIXELGYM_BINARY
"""
import re
import subprocess
import sys
from pathlib import Path

SHARED = re.compile(r"(\.\./)+shared\b|\bshared/(design|peers)\b")
MACHINE_PATH = re.compile(r"(?<![\w.~$/-])/(work|root|home|Users)/")
TMP_PATH = re.compile(r"(?<![\w.~$/-])/tmp/")
ISSUE = re.compile(r"\b(issues?\s*#?\s*\d+|issues/\d+|PRs?\s*#?\d+)\b", re.IGNORECASE)
HASH_NUMBER = re.compile(r"(?<![\w&#])#\d+\b")
LAB_NOTE = re.compile(r"\b(this|last|previous|earlier) session\b|\bthis (\d+-core )?VM\b",
                      re.IGNORECASE)
DATE = re.compile(r"(?<![\w/-])20\d\d-[01]\d-[0-3]\d\b")
ENV_ID = re.compile(r"\b([A-Z][A-Za-z0-9]*)-v(\d+)\b")
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
CODE_SPAN = re.compile(r"`[^`]*`")


def registered_versions(pixelgym):
    """{name: newest version} over the ids `pixelgym list` prints, one per line, first."""
    listing = subprocess.run([pixelgym, "list"], check=True, capture_output=True, text=True).stdout
    newest = {}
    for line in listing.splitlines():
        match = ENV_ID.fullmatch(line.split()[0]) if line.split() else None
        if match:
            name, version = match.group(1), int(match.group(2))
            newest[name] = max(version, newest.get(name, version))
    if not newest:
        sys.exit(f"{pixelgym} list printed no ids:\n{listing}")
    return newest


def slug(heading):
    """The anchor GitHub gives a heading."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def anchors(path, cache={}):
    if path not in cache:
        found, fenced = set(), False
        for line in path.read_text(encoding="utf-8").splitlines():
            if line.lstrip().startswith("```"):
                fenced = not fenced
            elif not fenced and line.startswith("#"):
                found.add(slug(line.lstrip("#")))
        cache[path] = found
    return cache[path]


def check_page(root, page, newest):
    relative = page.relative_to(root).as_posix()
    is_record = relative.startswith("docs/experiments/")
    problems = []
    fenced = False
    versions = False
    headline = False
    previous = ""
    for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), start=1):
        def report(rule, found):
            problems.append(f"{relative}:{number}: {rule}: {found!r} in: {line.strip()[:160]}")

        if line.lstrip().startswith("```"):
            fenced = not fenced
            previous = ""
            continue
        if re.search(r"<!-- older ids: \S", line):
            versions = True
        if "<!-- /older ids -->" in line:
            versions = False
        if "<!-- headline figures" in line:
            headline = True
        if "<!-- end of headline figures -->" in line:
            headline = False
        prose = "" if fenced else CODE_SPAN.sub("``", line)

        for match in SHARED.finditer(line):
            report("shared folder (outside the repository)", match.group(0))
        for match in MACHINE_PATH.finditer(line):
            report("absolute path of a machine", match.group(0))
        if not fenced:
            for match in TMP_PATH.finditer(line):
                report("/tmp path outside a command block", match.group(0))
        for match in ISSUE.finditer(line):
            report("issue number", match.group(0))
        for match in HASH_NUMBER.finditer(prose):
            report("issue number", match.group(0))
        for match in LAB_NOTE.finditer(line):
            report("lab note (who measured when)", match.group(0))
        # The same words wrapped over two lines ("this 2-core" / "VM", "issue" / "12").
        joined = previous + " " + line.lstrip()
        for pattern, rule in ((LAB_NOTE, "lab note (who measured when)"), (ISSUE, "issue number")):
            for match in pattern.finditer(joined):
                if match.start() < len(previous) < match.end():
                    report(rule + ", over two lines", match.group(0))
        previous = "" if fenced else line.rstrip()
        if not is_record:
            for match in DATE.finditer(line):
                report("date of a measurement (records go to docs/experiments/)", match.group(0))
        if not (versions or headline or is_record):
            for match in ENV_ID.finditer(line):
                name, version = match.group(1), int(match.group(2))
                if name in newest and version < newest[name]:
                    report(f"out-of-date id (use {name}-v{newest[name]})", match.group(0))
        if not fenced:
            for match in LINK.finditer(CODE_SPAN.sub("``", line)):
                target = match.group(1)
                if re.match(r"[a-z]+:", target):
                    continue
                file_part, _, anchor = target.partition("#")
                linked = (page.parent / file_part).resolve() if file_part else page
                if not linked.exists():
                    report("broken link (no such file)", target)
                elif anchor and linked.suffix == ".md" and anchor not in anchors(linked):
                    report("broken link (no such heading)", target)
    if fenced:
        problems.append(f"{relative}: a ``` block is not closed")
    return problems


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    root, pixelgym = Path(sys.argv[1]).resolve(), sys.argv[2]
    newest = registered_versions(pixelgym)
    # The Python package's docstrings are what help(pixelgym) shows: read as pages too.
    pages = ([root / "README.md"] + sorted((root / "docs").rglob("*.md"))
             + sorted((root / "python" / "pixelgym").glob("*.py")))
    problems = [problem for page in pages for problem in check_page(root, page, newest)]
    for problem in problems:
        print(problem)
    print(f"{len(pages)} pages, {len(problems)} problems; newest registered versions: "
          + ", ".join(f"{name}-v{version}" for name, version in sorted(newest.items())
                      if version > 0))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
