"""Shared helpers for the spec-checker and traceability tests.

Fixture trees live in fixtures/spec_*: ``spec_valid`` is a complete miniature repository
(spec/, models/, cpp/, proofs/, results/); every other ``spec_<case>`` directory holds
only the files that differ from it (one broken thing each). ``tree(case)`` copies the
valid tree, lays the case's files over it and adds the project's real JSON schemas, so
the schemas under test are the ones in spec/schemas.
"""
from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
REPO = TESTS.parents[1]
FIXTURES = TESTS / "fixtures"
sys.path.insert(0, str(REPO / "testgen"))

from railproof_testgen.__main__ import main  # noqa: E402


@pytest.fixture
def tree(tmp_path):
    """tree(*cases) -> Path of a fresh repository root built from spec_valid + overlays."""

    def make(*cases):
        root = tmp_path / "repo"
        if root.exists():
            shutil.rmtree(root)
        shutil.copytree(FIXTURES / "spec_valid", root)
        for case in cases:
            overlay = FIXTURES / f"spec_{case}"
            assert overlay.is_dir(), f"no fixture {overlay}"
            shutil.copytree(overlay, root, dirs_exist_ok=True)
        shutil.copytree(REPO / "spec" / "schemas", root / "spec" / "schemas",
                        dirs_exist_ok=True)
        return root

    return make


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
