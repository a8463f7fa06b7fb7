"""The fixture tree of the evidence tests (fixtures/evidence, see its README.md) and helpers
to copy, edit and read it. Imported by test_evidence.py and test_evidence_chapters.py."""
from __future__ import annotations

import html as html_mod
import json
import re
import shutil
from pathlib import Path

from railproof_testgen import evidence

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
FIX = HERE / "fixtures" / "evidence"
SPEC, RESULTS, MODELS = FIX / "spec", FIX / "results", FIX / "models"
AWKWARD = FIX / "junit_names"     # JUnit files with names no directive option can carry


def read_json(p: Path):
    return json.loads(p.read_text(encoding="utf-8"))


def write_json(p: Path, data) -> None:
    p.write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")


def edit_json(p: Path, change) -> None:
    data = read_json(p)
    change(data)
    write_json(p, data)


def edit_text(p: Path, old: str, new: str) -> None:
    text = p.read_text(encoding="utf-8")
    assert old in text, f"{old!r} not in {p}"
    p.write_text(text.replace(old, new), encoding="utf-8")


def repo_copy(tmp: Path, with_models: bool = True) -> Path:
    """A repository root holding the evidence sources and the fixture's models."""
    root = tmp / "repo"
    shutil.copytree(REPO / "evidence", root / "evidence", ignore=shutil.ignore_patterns("__pycache__"))
    if with_models:
        shutil.copytree(MODELS, root / "models")
    return root


def tree(tmp: Path) -> tuple:
    """(spec, results, repo): a fresh copy of the fixture to edit."""
    tmp.mkdir(parents=True, exist_ok=True)
    spec, results = tmp / "spec", tmp / "results"
    shutil.copytree(SPEC, spec)
    shutil.copytree(RESULTS, results)
    return spec, results, repo_copy(tmp)


def add_ctest_entry(results: Path, name: str, status: str = "run", failure: str = "") -> None:
    """Append an entry to the ctest JUnit file (failure: the text of a failed entry)."""
    body = f'<failure message=""/><system-out>{failure}</system-out>' if status == "fail" else "<system-out/>"
    edit_text(results / "tests" / "ctest.junit.xml", "</testsuite>",
              f'\t<testcase name="{name}" classname="{name}" time="0.01" status="{status}">{body}</testcase>\n'
              "</testsuite>")


def context(spec=SPEC, results=RESULTS, repo=None, tmp=None):
    return evidence.context(spec, results, repo or repo_copy(tmp))


def assert_fails(ctx, *problems: str) -> None:
    """The verdict is FAIL and every problem is among its reasons (word for word)."""
    assert ctx.verdict == "FAIL"
    missing = [p for p in problems if p not in ctx.problems]
    assert not missing, (missing, ctx.problems)


def text_of(html: str) -> str:
    return " ".join(html_mod.unescape(re.sub(r"<[^>]+>", " ", html)).split())


def table_rows(html: str) -> list:
    """The rows of every need table in html, each a list of cell texts."""
    rows = []
    for tb in re.findall(r'<table class="NEEDS_(?:TABLE|DATATABLES)[^"]*".*?</table>', html, re.S):
        for tr in re.findall(r"<tr[^>]*>(.*?)</tr>", tb, re.S):
            rows.append([text_of(c) for c in re.findall(r"<t[dh][^>]*>(.*?)</t[dh]>", tr, re.S)])
    return rows


def needs(html_dir: Path) -> dict:
    data = read_json(html_dir / "needs.json")
    return next(iter(data["versions"].values()))["needs"]
