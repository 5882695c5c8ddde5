"""The product speaks in the present tense: no tracked file numbers the project's work periods or
its tickets.

History lives in ``CHANGELOG.md`` (by version) and in git. Every other tracked text file (code,
tests, docs, data notes, configuration) is searched line by line, case-insensitively, for a
work-period word or a ticket word directly followed by a number: the forms found in the history
were a space, a hyphen, a colon, a quote or a ``#`` between the word and the number (``... 21``,
``...-4``, ``...": 18``, ``... #7``). A failure lists every ``file:line`` that matches.
"""

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
ALLOWED = {"CHANGELOG.md"}

# Written in pieces so that this file does not match its own pattern.
_WORDS = "|".join(("sess" + "ions?", "iss" + "ues?"))
MARKER = re.compile(r"\b(" + _WORDS + r")[\"':\- #]*[0-9]", re.IGNORECASE)


def tracked_files():
    """Paths of the files git tracks under the repository root (relative, posix)."""
    try:
        out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True,
                             check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout: the tracked files are unknown")
    return [p for p in out.decode().split("\0") if p]


def marker_lines(paths):
    """``file:line: text`` of every line of the text files in ``paths`` that holds a marker."""
    hits = []
    for rel in paths:
        if rel in ALLOWED:
            continue
        path = ROOT / rel
        if not path.is_file():              # deleted in the work tree, not yet in git's index
            continue
        data = path.read_bytes()
        if b"\0" in data[:8192]:            # binary (tables, images)
            continue
        for number, line in enumerate(data.decode("utf-8", "replace").splitlines(), 1):
            if MARKER.search(line):
                hits.append(f"{rel}:{number}: {line.strip()[:120]}")
    return hits


def test_marker_pattern_catches_every_form():
    """The pattern catches the forms used and leaves ordinary uses of the words alone."""
    word_s, word_i = "Sess" + "ion", "iss" + "ue"
    for text in (f"{word_s} 21", f"{word_s}s 8/9", f"the {word_s.lower()}-4 host",
                 f'"{word_s.lower()}": 18,', f"{word_i} 14", f"{word_i.upper()}S 13, 15",
                 f"{word_i} #7", f"{word_i}-7 lattice", f"{word_i}#3"):
        assert MARKER.search(text), text
    for text in ('scope="session"', "a known issue with gmsh", "per session of work",
                 "t" + word_i + " 3", "ob" + word_s.lower() + " 2"):
        assert not MARKER.search(text), text


def test_no_tracked_file_numbers_work_periods_or_tickets():
    hits = marker_lines(tracked_files())
    assert not hits, f"{len(hits)} line(s) number a work period or a ticket:\n" + "\n".join(hits)
