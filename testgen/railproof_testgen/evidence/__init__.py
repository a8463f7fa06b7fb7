"""Render the assessor's evidence package and hash it into a manifest.

``python -m railproof_testgen evidence --spec SPEC --results RESULTS --src REPO --out OUT``

1. reads spec/ and the build's results directory (inputs.py; the test suite's results:
   junit.py), driven by the capability registry (results/registry.json);
2. computes everything the pages show and every reason for a FAIL verdict once
   (context.py and its parts: modelcheck, generation, tests, analysis, boundaries, and one
   chapter per registered capability: chapters/);
3. copies every input verbatim to OUT/inputs, copies the Sphinx sources of REPO/evidence to
   OUT/src, writes the generated reStructuredText pages beside them from the Jinja templates
   in evidence/templates, runs ``sphinx-build -b html`` (Sphinx + sphinx-needs +
   sphinx-test-reports) into OUT/html, and writes OUT/evidence.json (verdict, reasons,
   counts), OUT/manifest.json and OUT/manifest.sha256 (render.py).

The evidence never runs a test: it reads the JUnit results of the build's one ctest run.
Malformed input stops the command with ``file: entry: reason`` before anything is written;
a missing, failed or violated result is rendered and makes the verdict FAIL.
"""
from __future__ import annotations

import shlex
from pathlib import Path

from .. import SPEC_DIR, add_command
from ..errors import PipelineError
from .context import Context
from .inputs import Inputs, load_inputs
from .junit import JUnitCase, parse_junit
from .render import EXCLUDED, check_toolchain, log, render_package
from .text import display_text, fmt_value, need_id, one_line, plain_option, rst_escape, safe_json_line

__all__ = ["Context", "Inputs", "JUnitCase", "build", "display_text", "fmt_value", "load_inputs",
           "need_id", "one_line", "parse_junit", "plain_option", "register", "rst_escape",
           "safe_json_line", "EXCLUDED"]


def _display_path(path: Path, repo_root: Path, placeholder: str) -> str:
    try:
        return path.resolve().relative_to(repo_root.resolve()).as_posix() or "."
    except ValueError:
        return placeholder


def _check_out_dir(out_dir: Path, repo_root: Path, spec_dir: Path, results_dir: Path) -> None:
    out = out_dir.resolve()
    if out == repo_root.resolve() or out in repo_root.resolve().parents:
        raise PipelineError(f"{out_dir}: output directory must not be the source tree or above it")
    for protected, what in ((repo_root / "evidence", "the evidence sources"),
                            (spec_dir, "the specification"), (results_dir, "the results")):
        p = protected.resolve()
        if out == p or p in out.parents or out in p.parents:
            raise PipelineError(f"{out_dir}: output directory must not overlap {what} ({protected})")


def replay_command(spec_dir: Path, results_dir: Path, repo_root: Path) -> str:
    """The command that renders this package again, with paths relative to the repository
    root (placeholders for paths outside it)."""
    args = [("--spec", _display_path(spec_dir, repo_root, "SPEC_DIR")),
            ("--results", _display_path(results_dir, repo_root, "RESULTS_DIR")),
            ("--src", "."), ("--out", "OUT_DIR")]
    return " \\\n    ".join(["PYTHONPATH=testgen python -m railproof_testgen evidence"]
                            + [f"{k} {shlex.quote(v)}" for k, v in args])


def context(spec_dir, results_dir, repo_root) -> Context:
    """The rendering context of the inputs, without rendering (for checks and tests)."""
    spec_dir, results_dir, repo_root = Path(spec_dir), Path(results_dir), Path(repo_root)
    return Context(load_inputs(spec_dir, results_dir, repo_root),
                   replay_command(spec_dir, results_dir, repo_root))


def build(spec_dir, results_dir, repo_root, out_dir) -> dict:
    spec_dir, results_dir = Path(spec_dir), Path(results_dir)
    repo_root, out_dir = Path(repo_root), Path(out_dir)
    _check_out_dir(out_dir, repo_root, spec_dir, results_dir)
    log(f"reading specification {spec_dir} and results {results_dir}")
    ctx = context(spec_dir, results_dir, repo_root)
    check_toolchain()
    c = ctx.counts
    log(f"rendering {c['capabilities']} capabilities, {c['requirements']} requirements, "
        f"{c['properties']} properties, {c['mutants']} mutants, {c['vectors']} vectors, "
        f"{c['ctest_entries']} ctest entries, {c['test_cases']} test cases, "
        f"{c['seeded_faults']} seeded faults, {c['analyses']} analyses")
    return render_package(ctx, repo_root / "evidence", out_dir)


def _run(a) -> int:
    res = build(a.spec, a.results, a.src, a.out)
    for p in res["summary"]["problems"]:
        log(f"FAIL: {p}")
    return 0


def register(sub):
    add_command(sub, "evidence", _run,
                "render the assessor's evidence package (Sphinx + sphinx-needs) and its manifest",
                """Render spec/ and the build's results into an HTML evidence package with
                Sphinx, sphinx-needs and sphinx-test-reports, and write a SHA-256 manifest. The
                verdict (PASS or FAIL, with every reason) is in OUT/evidence.json.""",
                spec=SPEC_DIR,
                results="the build's results directory (registry.json, trace.json, spin/, vectors/, "
                        "tests/, analysis/, proofs/, layout.json, tool-versions.json, ...)",
                src="repository root (its evidence/ holds the sources)",
                out="output directory (inputs/, src/, html/, manifest)")
