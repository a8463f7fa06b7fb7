"""Shared helpers for the spec-checker and traceability tests.

Fixture trees live in fixtures/spec_*: ``spec_valid`` is a complete miniature repository
(spec/, models/, cpp/, proofs/, results/); every other ``spec_<case>`` directory holds
only what differs from it (one broken thing each): files, and in ``edits.yaml`` the text
edits of the valid tree's files ({file, old, new}: the first old text replaced). ``tree(case)``
copies the valid tree, lays the case over it and adds the project's real JSON schemas, so
the schemas under test are the ones in spec/schemas.
"""
from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest
import yaml

TESTS = Path(__file__).resolve().parent
REPO = TESTS.parents[1]
FIXTURES = TESTS / "fixtures"
sys.path.insert(0, str(REPO / "testgen"))

from railproof_testgen.__main__ import main  # noqa: E402

EDITS = "edits.yaml"  # the text edits of an overlay


def edit(path: Path, old: str, new: str):
    """Replace the first occurrence of old (which must occur) in the text file path by new."""
    text = path.read_text(encoding="utf-8")
    assert old in text, f"{old!r} not in {path}"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")


@pytest.fixture
def tree(tmp_path):
    """tree(*cases, edits=()) -> Path of a fresh repository root built from spec_valid +
    overlays, with the text edits (file, old, new) applied last."""

    def make(*cases, edits=()):
        root = tmp_path / "repo"
        if root.exists():
            shutil.rmtree(root)
        shutil.copytree(FIXTURES / "spec_valid", root)
        for case in cases:
            overlay = FIXTURES / f"spec_{case}"
            assert overlay.is_dir(), f"no fixture {overlay}"
            shutil.copytree(overlay, root, dirs_exist_ok=True, ignore=shutil.ignore_patterns(EDITS))
            if (overlay / EDITS).is_file():
                for e in yaml.safe_load((overlay / EDITS).read_text(encoding="utf-8")):
                    edit(root / e["file"], e["old"], e["new"])
        shutil.copytree(REPO / "spec" / "schemas", root / "spec" / "schemas",
                        dirs_exist_ok=True)
        for file, old, new in edits:
            edit(root / file, old, new)
        return root

    return make


def fails_with(r, *findings):
    """The run r failed (exit status 1) and names every finding (file suffix, entry, reason
    fragment) in an error line."""
    assert r.rc == 1, r.err
    for finding in findings:
        assert r.has(*finding), (finding, r.err)


class CliResult:
    def __init__(self, rc, out, err):
        self.rc, self.out, self.err = rc, out, err
        self.lines = [ln for ln in err.splitlines() if ln and not ln.startswith("warning: ")]
        self.warnings = [ln[len("warning: "):] for ln in err.splitlines()
                         if ln.startswith("warning: ")]

    def has(self, file_suffix, entry, fragment):
        """True if an error line names a file ending in file_suffix, the entry and the
        reason fragment."""
        return any(_matches(ln, file_suffix, entry, fragment) for ln in self.lines)

    def warned(self, file_suffix, entry, fragment):
        return any(_matches(ln, file_suffix, entry, fragment) for ln in self.warnings)


def _matches(line, file_suffix, entry, fragment):
    parts = line.split(": ", 2)
    return (len(parts) == 3 and parts[0].endswith(file_suffix) and entry in parts[1]
            and fragment in parts[2])


@pytest.fixture
def cli(capsys):
    """cli(*argv) runs the command line in-process and returns a CliResult."""

    def run(*argv):
        rc = main([str(a) for a in argv])
        cap = capsys.readouterr()
        return CliResult(rc, cap.out, cap.err)

    return run
