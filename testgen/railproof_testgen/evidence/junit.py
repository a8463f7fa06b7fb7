"""The test suite's results: the JUnit file of the build's one ctest run and the per-entry
detail files (GoogleTest XML, pytest JUnit) it names.

The build's ``test-results`` step runs ctest once and writes ``results/tests/ctest.junit.xml``
(one ``<testcase>`` per ctest entry). Each entry is classified by its name (``ENTRY_KINDS``,
first match wins); the kinds with a detail file name where the entry wrote it:

==========================  ==============================================
ctest entry                 detail file (under results/)
==========================  ==============================================
``<set>.<Suite>.<Test>``    ``tests/unit/<set>/<entry>.xml``
``conformance_<cap>``       ``tests/conformance/<cap>.xml`` (a test per vector)
``conformance_fault_<F>``   ``tests/faults/conformance_<F>.xml``
``unit_fault_<F>``          ``tests/faults/unit_<F>.xml``
``testgen.<file>``          ``tests/testgen/<file>.xml``
==========================  ==============================================

Only the detail files of this run's entries are read; any other XML file below tests/ is
left out of the package (``TestRun.ignored``), since nothing says it belongs to this run.
"""
from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import PipelineError

CTEST_JUNIT = "tests/ctest.junit.xml"
FAILED = ("failure", "error")

# (kind, heading, name pattern, detail file) in the order they are tried.
ENTRY_KINDS = [
    ("conformance", "Conformance: vector replay", r"conformance_(?P<cap>[a-z]+)",
     "tests/conformance/{cap}.xml"),
    ("conformance_check", "Conformance: runner checks", r"conformance_(?P<cap>[a-z]+)_rejects_\w+", None),
    ("fault_control", "Seeded faults: schemata build with no fault selected",
     r"(?:unit|conformance)_faults_none_selected_(?P<cap>[a-z]+)", None),
    ("fault", "Seeded faults: runs with one fault active",
     r"(?P<via>conformance|unit)_fault_(?P<fault>\w+)", "tests/faults/{via}_{fault}.xml"),
    ("fault_build", "Seeded faults: production and schemata builds",
     r"(?:no_seeded_fault_in|seeded_fault_selector_in)_\w+", None),
    ("testgen", "Tooling tests (pytest)", r"testgen\.(?P<file>\w+)", "tests/testgen/{file}.xml"),
    ("unit", "Unit tests (GoogleTest)", r"(?P<set>\w+)\.(?P<suite>[^.]+)\.(?P<test>.+)",
     "tests/unit/{set}/{name}.xml"),
    ("fuzz", "Fuzzing", r".*fuzz.*", None),
    ("check", "Pipeline and tool checks", r".*", None),
]
KIND_TITLES = {k: title for k, title, _, _ in ENTRY_KINDS}


@dataclass
class JUnitCase:
    suite: str
    classname: str
    name: str
    result: str       # passed | failure | error | skipped
    time: str
    properties: dict = field(default_factory=dict)   # <properties><property name= value=>
    message: str = ""  # message attribute of <failure>/<error>/<skipped>
    text: str = ""     # text of <failure>/<error>/<skipped>
    system_out: str = ""
    index: int = 0     # position among the <testcase> children of its suite
    file: str = ""     # the file attribute GoogleTest writes (the test's source)

    @property
    def failed(self) -> bool:
        return self.result in FAILED

    def keys(self) -> set:
        """The names a trace.json unit link may use for this case: ``Suite.Test`` (GoogleTest)
        or ``tests/test_x.py::test_y`` (pytest)."""
        keys = {f"{self.classname}.{self.name}", f"{self.classname}::{self.name}",
                f"{self.suite}.{self.name}"}
        if "." in self.classname:   # pytest: tests.test_x + test_y <-> tests/test_x.py::test_y
            keys.add(self.classname.replace(".", "/") + ".py::" + self.name)
        return keys

    def matches(self, test: str, file: str = "") -> bool:
        """True if a trace.json unit link (test name, source file) names this case; the file
        decides between cases of the same name in two test sets."""
        keys = self.keys()
        hit = test in keys or test == self.name or any(
            test.endswith("/" + k) for k in keys if "::" in k)
        if hit and file and self.file:
            return self.file == file or self.file.endswith("/" + file)
        return hit


@dataclass
class JUnitSuite:
    name: str
    cases: list            # [JUnitCase]
    nested: bool           # below another <testsuite>
    top_index: int | None  # position among the file's top-level suites (None when nested)


@dataclass
class JUnitFile:
    rel: str          # relative to the results directory (posix)
    suites: list      # [JUnitSuite] (every suite with at least one case, nested ones flattened)
    error_elements: int = 0
    reports_view: list | None = None   # sphinx-test-reports' own parse of the file
    reports_error: str = ""            # why that parse is not available

    @property
    def cases(self) -> list:
        return [c for s in self.suites for c in s.cases]


@dataclass
class Entry:
    """One ctest entry of the run."""
    name: str
    result: str
    kind: str
    groups: dict          # the named groups of the pattern (cap, fault, via, set, file)
    detail: str | None    # its detail file, relative to results/ (None: the kind has none)
    output: str = ""      # ctest's captured output (failure text or system-out)


@dataclass
class TestRun:
    ctest: JUnitFile | None = None
    entries: list = field(default_factory=list)   # [Entry] in the order of the ctest file
    details: dict = field(default_factory=dict)   # rel -> JUnitFile (present detail files)
    ignored: list = field(default_factory=list)   # XML files below tests/ of no entry of the run


def parse_junit(path: Path, rel: str, reports_view: bool = True) -> JUnitFile:
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise PipelineError(f"{path}: malformed JUnit XML: {exc}") from None
    if root.tag not in ("testsuites", "testsuite"):
        raise PipelineError(f"{path}: not JUnit XML (root element <{root.tag}>)")
    suites, errors = [], 0
    top = [root] if root.tag == "testsuite" else root.findall("testsuite")
    for k, ts in enumerate(top):
        # Suites nested below the top level are flattened and flagged: sphinx-test-reports
        # 1.3.1 looks suites up by name at the top level only.
        for s in ts.iter("testsuite"):
            cases = [_case(s, tc, i) for i, tc in enumerate(s.findall("testcase"))]
            errors += sum(c.result == "error" for c in cases)
            if cases:
                nested = s is not ts
                suites.append(JUnitSuite(s.get("name", "unknown"), cases, nested,
                                         None if nested else k))
    view, why = _reports_view(path) if reports_view else (None, "not rendered as test needs")
    return JUnitFile(rel, suites, errors, view, why)


def _case(s, tc, index: int) -> JUnitCase:
    outcome, result = None, "passed"
    for tag in ("failure", "error", "skipped"):
        outcome = tc.find(tag)
        if outcome is not None:
            result = tag
            break
    props = {}
    for pr in tc.iter("property"):
        if pr.get("name") is not None:
            props.setdefault(pr.get("name"), pr.get("value", pr.text or ""))
    out = tc.find("system-out")
    return JUnitCase(
        s.get("name", "unknown"), tc.get("classname", "unknown"), tc.get("name", "unknown"),
        result, tc.get("time", ""), props,
        message=(outcome.get("message", "") if outcome is not None else ""),
        text=((outcome.text or "") if outcome is not None else ""),
        system_out=((out.text or "") if out is not None else ""), index=index,
        file=tc.get("file", ""))


def _reports_view(path: Path):
    """sphinx-test-reports' own parse of a JUnit file, as its directives will see it, or
    (None, reason) when its parser cannot read the file (it raises on, for example, a
    non-numeric ``time`` or ``line`` attribute)."""
    try:
        from sphinxcontrib.test_reports.junitparser import JUnitParser
    except ImportError:
        return None, "sphinx-test-reports is not installed"
    try:
        return JUnitParser(str(path)).parse(), ""
    except Exception as exc:  # noqa: BLE001 - any failure of the third-party parser
        return None, f"the JUnit parser of sphinx-test-reports fails on this file ({type(exc).__name__})"


def classify(name: str) -> tuple:
    """(kind, groups, detail file or None) of a ctest entry name."""
    for kind, _title, pattern, detail in ENTRY_KINDS:
        m = re.fullmatch(pattern, name)
        if m:
            groups = {k: v for k, v in m.groupdict().items() if v is not None}
            return kind, groups, detail.format(name=name, **groups) if detail else None
    raise AssertionError("the last pattern matches every name")


def load_run(results_dir: Path, missing: list) -> TestRun:
    """The ctest file, its entries and the detail files they name (missing files are noted
    in ``missing``; the entries keep their expected path)."""
    run = TestRun()
    tdir = results_dir / "tests"
    path = results_dir / CTEST_JUNIT
    if not path.is_file():
        missing.append(f"results/{CTEST_JUNIT}: the build's one ctest run (target test-results) "
                       "wrote no results")
        return run
    run.ctest = parse_junit(path, CTEST_JUNIT, reports_view=False)
    seen = set()
    for c in run.ctest.cases:
        if c.name in seen:
            raise PipelineError(f"{path}: {c.name}: two ctest entries of the same name")
        seen.add(c.name)
        kind, groups, detail = classify(c.name)
        run.entries.append(Entry(c.name, c.result, kind, groups, detail,
                                 "\n".join(t for t in (c.message, c.text, c.system_out) if t.strip())))
        if detail and (results_dir / detail).is_file():
            run.details[detail] = parse_junit(results_dir / detail, detail,
                                              reports_view=kind != "fault")
    named = set(run.details) | {CTEST_JUNIT}
    run.ignored = sorted(p.relative_to(results_dir).as_posix() for p in tdir.rglob("*.xml")
                         if p.is_file() and p.relative_to(results_dir).as_posix() not in named)
    return run
