"""Render the assessor's evidence package and hash it into a manifest.

``python -m railproof_testgen evidence --spec SPEC --results RESULTS --src REPO --out OUT``

1. reads spec/ (requirements, hazards, assumptions, parameters) and the pipeline's result
   files (spin/*.json, vectors/*.jsonl + *.coverage.json, tests/**/*.xml, analysis/*.json,
   trace.json; formats: spec/design/tg.md §8) plus optional tool versions;
2. copies every input verbatim to OUT/inputs, copies the Sphinx sources of REPO/evidence to
   OUT/src and writes the generated reStructuredText pages beside them (rendered from the
   Jinja templates in evidence/templates): one sphinx-needs need per requirement, hazard,
   assumption, model property, named model assertion, mutant, vector and analysis result,
   one page per requirement with its properties, vectors, conformance and unit results,
   and the JUnit results through sphinx-test-reports (a test whose name or result
   sphinx-test-reports cannot address exactly is rendered from this module's own parse of
   the XML as a need of the same type, see ``Model._suite_why`` and ``Model._case_why``);
3. runs ``sphinx-build -b html`` into OUT/html with SOURCE_DATE_EPOCH, PYTHONHASHSEED and the
   locale fixed, fails on any error, and writes OUT/manifest.json + OUT/manifest.sha256
   (SHA-256 of every input copy, generated source and rendered file) and OUT/evidence.json
   (machine-readable verdict and counts).

The HTML is produced by Sphinx alone; this module only writes reStructuredText.
"""
from __future__ import annotations

import hashlib
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path

from . import spec as spec_mod
from .errors import PipelineError, SpecError

MANIFEST_SCHEMA = "railproof/manifest/1"
TRACE_SCHEMA = "railproof/trace/1"
# 1980-01-01T00:00:00Z: a fixed date for Sphinx's date-dependent values (the package shows
# no build date at all; this only keeps any date Sphinx computes independent of the clock).
SOURCE_DATE_EPOCH = "315532800"

EXCLUDED = {
    ".doctrees/": "Sphinx's pickled build environment: holds absolute paths and object "
                  "reprs, differs between build directories; deleted after the build",
    "html/.buildinfo": "Sphinx's incremental-build stamp: hash of the configuration, which "
                       "includes the absolute path of the input copies (tr_rootdir)",
    "html/schema_violations.json": "sphinx-needs' schema validation report: records the "
                                   "validation's wall-clock duration and rate (no setting turns "
                                   "this off); its findings are Sphinx warnings, which the build "
                                   "requires to be absent",
    "sphinx-output.log": "console output of sphinx-build: names absolute paths",
    "sphinx-warnings.log": "warnings of sphinx-build: names absolute paths (must be empty)",
    "**/__pycache__/": "Python byte code (not written: PYTHONDONTWRITEBYTECODE=1)",
}

# Verification configurations of models/mb.pml (its header comment and
# spec/design/mb.md §5), in the order the chapter lists them.
MB_CONFIGURATIONS = {
    "default": "the full model: every train of the model bounds and every environment command "
               "(possession, siding route, radio cells, boundary) with every fault",
    "CORE": "2 trains over the whole line; every report, tracking, set-back and telegram fault "
            "(loss, delay, re-ordering); no infrastructure commands",
    "TRIO": "3 trains with every fault of CORE, confined to the first blocks: the next radio cell "
            "is never secured, so the handover point ends their run (the platform, the only fixed "
            "block and set-back section, lies before it)",
    "FEATURE_POSS": "2 trains; possessions requested, confirmed and cancelled at any time "
                    "(telegrams lost but not held back)",
    "FEATURE_ROUTE": "2 trains; the siding route over the points requested and freed at any time "
                     "(telegrams lost but not held back)",
    "FEATURE_RADIO": "2 trains; radio cells secured and the boundary accepted at any time "
                     "(telegrams lost but not held back)",
    "FAIR": "a healthy system: every report and telegram arrives in its cycle, no possession or "
            "siding request; for the progress property",
    "TRAINS2": "the full model with 2 trains (cost table)",
    "TRAINS4": "the full model with 4 trains (cost table)",
}

_NEED_ID_BAD = re.compile(r"[^A-Za-z0-9_-]+")
_RST_SPECIAL = re.compile(r"([\\`*_|])")
_RST_BLOCK_START = re.compile(r"^(?:[-+•]\s|\d+[.)]\s|[a-zA-Z#][.)]\s|\.\.(?:\s|$)|::|>>>)")


def _log(msg: str) -> None:
    print(f"evidence: {msg}", file=sys.stderr, flush=True)


# --------------------------------------------------------------------------------------
# small helpers


def need_id(*parts: str, upper: bool = True) -> str:
    """A sphinx-needs id from free text: [A-Za-z0-9_-] only (upper case unless upper=False),
    starting with a letter; matches needs_id_regex in evidence/conf.py."""
    text = "_".join(p for p in parts if p)
    nid = _NEED_ID_BAD.sub("_", text.upper() if upper else text).strip("_")
    if not nid or not nid[0].isalpha():
        nid = "X_" + nid
    return nid.ljust(3, "_")     # needs_id_regex: at least three characters


def _no_dynamic(text: str) -> str:
    """sphinx-needs reads ``[[...]]`` in a need's fields and content as a dynamic function
    call; adjacent brackets are spaced apart so input text is never executed."""
    text = re.sub(r"\[(?=\[)", "[ ", text)
    return re.sub(r"\](?=\])", "] ", text)


def rst_escape(value) -> str:
    """Escape inline reStructuredText markup characters; newlines become spaces; a leading
    list, enumeration or comment marker is escaped so a table cell stays one paragraph;
    ``[[``/``]]`` are spaced apart (see _no_dynamic)."""
    text = _RST_SPECIAL.sub(r"\\\1", " ".join(str(value).split()))
    if _RST_BLOCK_START.match(text):
        text = "\\" + text
    return _no_dynamic(text)


def one_line(value) -> str:
    """Directive arguments and option values: one line, no leading/trailing blanks, no
    ``[[``/``]]`` (see _no_dynamic)."""
    return _no_dynamic(" ".join(str(value).split()))


def display_text(value) -> str:
    """Arbitrary text (a test name from a JUnit file) shown on one line: every character
    that would break a line or is invisible (controls, Unicode line and paragraph
    separators, tabs) is written as its Python escape (``\\n``, ``\\t``, ``\\u2028``),
    leading and trailing blanks are kept visible the same way, and ``[[``/``]]`` are spaced
    apart. The exact text is shown beside it in a literal block."""
    text = str(value)
    out = []
    for i, ch in enumerate(text):
        if ch == " " and (i == 0 or i == len(text) - 1):
            out.append("\\x20")
        elif ch.isprintable():
            out.append(ch)
        else:
            out.append(repr(ch)[1:-1])
    return _no_dynamic("".join(out)) or "(empty)"


_PLAIN = re.compile(r"[!-~](?:[ -~]*[!-~])?")
_NOT_PLAIN = re.compile(r"  |\[\[|\]\]|<<|>>")


def plain_option(value: str) -> bool:
    """True if value passes unchanged through a one-line reStructuredText directive option
    and a sphinx-needs field: printable ASCII, no leading/trailing or double blanks, no
    dynamic-function or variant markers."""
    return bool(_PLAIN.fullmatch(value)) and not _NOT_PLAIN.search(value)


def fmt_value(v) -> str:
    """Numbers for tables: integers as is, floats with six significant digits or in
    scientific notation, booleans as yes/no, lists joined by commas."""
    if v is None:
        return "n/a"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if v == 0.0:
            return "0"
        if 1e-3 <= abs(v) < 1e6:
            return f"{v:.6g}"
        return f"{v:.3e}"
    if isinstance(v, (list, tuple)):
        return ", ".join(fmt_value(x) for x in v)
    if isinstance(v, dict):
        return ", ".join(f"{k}={fmt_value(x)}" for k, x in v.items())
    return str(v)


def _count(items) -> dict:
    out: dict = {}
    for x in items:
        out[x] = out.get(x, 0) + 1
    return out


def _flatten(obj: dict, prefix: str = "") -> dict:
    """{"a": {"b": 1}, "c": [1, 2]} -> {"a.b": 1, "c": [1, 2]} (lists kept as values)."""
    out: dict = {}
    for k, v in obj.items():
        key = f"{prefix}.{k}" if prefix else str(k)
        if isinstance(v, dict) and v:
            out.update(_flatten(v, key))
        else:
            out[key] = v
    return out


def safe_json_line(obj) -> str:
    """One JSON line for display inside need content. sphinx-needs treats ``[[`` ... ``]]``
    in need content as a dynamic function, so adjacent brackets are spaced apart (the
    verbatim file is linked beside it)."""
    return _no_dynamic(json.dumps(obj, sort_keys=True, ensure_ascii=False))


def sha256_file(path: Path) -> str:
    h = hashlib.sha256()
    with Path(path).open("rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def _load_json(path: Path, what: str):
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise PipelineError(f"{path}: {what} not found") from None
    except OSError as exc:
        raise PipelineError(f"{path}: cannot read {what}: {exc.strerror}") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise PipelineError(f"{path}: malformed JSON at line {exc.lineno}: {exc.msg}") from None


def _require(cond: bool, path: Path, entry: str, reason: str) -> None:
    if not cond:
        raise PipelineError(f"{path}: {entry}: {reason}")


# --------------------------------------------------------------------------------------
# inputs


@dataclass
class InputFile:
    source: Path      # where it was read
    rel: str          # path under OUT/inputs (posix)


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


@dataclass
class Inputs:
    spec_dir: Path
    results_dir: Path
    repo_root: Path
    requirements: list = field(default_factory=list)
    hazards: list = field(default_factory=list)
    assumptions: list = field(default_factory=list)
    parameters: dict = field(default_factory=dict)
    trace: dict = field(default_factory=dict)
    spin: list = field(default_factory=list)          # [(rel, data)]
    vectors: list = field(default_factory=list)       # [(rel, header, [vector])]
    coverage: list = field(default_factory=list)      # [(rel, data)]
    junit: list = field(default_factory=list)         # [JUnitFile]
    analysis: list = field(default_factory=list)      # [(rel, data)]
    scenario_plots: list = field(default_factory=list)  # [(name, Path of scenarios/<name>.svg)]
    scenario_logs: dict = field(default_factory=dict)   # name -> rel of scenarios/<name>.log.json
    proofs: list = field(default_factory=list)          # [(rel, data)] of proofs/*.json
    braking_plots: list = field(default_factory=list)   # [(name, Path of braking/<name>.svg)]
    odometry_plots: list = field(default_factory=list)  # [(name, Path of odometry/<name>.svg)]
    crossing_plots: list = field(default_factory=list)  # [(name, Path of level_crossing/<name>.svg)]
    peer_check: list = field(default_factory=list)      # rows of the level-crossing peer cross-check
    justifications: dict = field(default_factory=dict)  # UR id -> entry (spec/justifications)
    model_sources: dict = field(default_factory=dict)   # model path -> text (None: not found)
    model_copies: dict = field(default_factory=dict)    # model path -> its copy under inputs/
    tool_versions: dict | None = None
    tool_versions_name: str | None = None
    files: list = field(default_factory=list)         # [InputFile]
    missing: list = field(default_factory=list)       # notes: inputs not available


def _rel(path: Path, base: Path) -> str:
    return path.relative_to(base).as_posix()


def _load_spec(inp: Inputs) -> None:
    spec_dir = inp.spec_dir
    if not spec_dir.is_dir():
        raise PipelineError(f"{spec_dir}: specification directory not found")
    req_files = spec_mod.spec_files(spec_dir, "requirements")
    if not req_files:
        raise PipelineError(f"{spec_dir / 'requirements'}: no requirement files (*.yaml) found")
    seen = set()
    for kind, key, target in (("requirements", "requirements", inp.requirements),
                              ("hazards", "hazards", inp.hazards),
                              ("assumptions", "assumptions", inp.assumptions)):
        files = spec_mod.spec_files(spec_dir, kind)
        if not files:
            inp.missing.append(f"spec/{kind}")
        for f in files:
            data = spec_mod.load_yaml(f)
            entries = data.get(key) or []
            if not isinstance(entries, list):
                raise SpecError(f, key, "must be a list")
            for i, e in enumerate(entries):
                if not isinstance(e, dict) or "id" not in e:
                    raise SpecError(f, f"{key}[{i}]", "entry needs an 'id'")
                if e["id"] in seen:
                    raise SpecError(f, e["id"], "duplicate id")
                seen.add(e["id"])
                target.append(dict(e, _file=f.name, _area=data.get("area", "")))
            inp.files.append(InputFile(f, f"spec/{_rel(f, spec_dir)}"))
    params = spec_mod.load_parameters(spec_dir)
    inp.parameters = params
    for area in sorted(params):
        f = Path(params[area]["file"])
        inp.files.append(InputFile(f, f"spec/{_rel(f, spec_dir)}"))
    if not params:
        inp.missing.append("spec/parameters")
    # Justifications of unreachable goals (optional: only needed when a goal is unreachable).
    for f in spec_mod.spec_files(spec_dir, "justifications"):
        data = spec_mod.load_yaml(f)
        entries = data.get("justifications") or []
        if not isinstance(entries, list):
            raise SpecError(f, "justifications", "must be a list")
        for i, e in enumerate(entries):
            if not isinstance(e, dict) or "id" not in e:
                raise SpecError(f, f"justifications[{i}]", "entry needs an 'id'")
            if e["id"] in inp.justifications:
                raise SpecError(f, e["id"], "duplicate id")
            inp.justifications[str(e["id"])] = dict(e, _file=f.name)
        inp.files.append(InputFile(f, f"spec/{_rel(f, spec_dir)}"))


def _load_trace(inp: Inputs) -> None:
    path = inp.results_dir / "trace.json"
    if not path.is_file():
        raise PipelineError(f"{path}: trace.json not found (the traceability step writes it; "
                            "run it before rendering the evidence)")
    data = _load_json(path, "trace.json")
    _require(isinstance(data, dict), path, "-", "top level must be an object")
    _require(data.get("schema") == TRACE_SCHEMA, path, "schema",
             f"expected {TRACE_SCHEMA!r}, got {data.get('schema')!r}")
    reqs = data.get("requirements")
    _require(isinstance(reqs, list), path, "requirements", "must be a list")
    for i, r in enumerate(reqs):
        _require(isinstance(r, dict) and "id" in r, path, f"requirements[{i}]", "needs an 'id'")
        _require(isinstance(r.get("links", {}), dict), path, r["id"], "'links' must be an object")
    inp.trace = data
    inp.files.append(InputFile(path, "results/trace.json"))


def _load_spin(inp: Inputs) -> None:
    files = sorted((inp.results_dir / "spin").glob("*.json"))
    if not files:
        inp.missing.append("results/spin/*.json (model checking)")
    for f in files:
        data = _load_json(f, "SPIN result")
        _require(isinstance(data, dict), f, "-", "top level must be an object")
        for key in ("properties", "mutants"):
            _require(isinstance(data.get(key, []), list), f, key, "must be a list")
        for i, p in enumerate(data.get("properties", [])):
            _require(isinstance(p, dict) and "name" in p and "verdict" in p, f,
                     f"properties[{i}]", "needs 'name' and 'verdict'")
        for i, m in enumerate(data.get("mutants", [])):
            _require(isinstance(m, dict) and "name" in m and "verdict" in m, f,
                     f"mutants[{i}]", "needs 'name' and 'verdict'")
        rel = _rel(f, inp.results_dir)
        inp.spin.append((rel, data))
        inp.files.append(InputFile(f, f"results/{rel}"))
        _load_model_source(inp, data.get("model"))


def _load_model_source(inp: Inputs, model) -> None:
    """The checked model's source, when the result names a file inside the source tree: its
    ``// @assert`` annotations name the model assertions; a verbatim copy goes to
    inputs/source/. Absent or outside the tree: the assertions are known only by the
    names that mutants and trace.json give them."""
    if not isinstance(model, str) or not model or model in inp.model_sources:
        return
    root = inp.repo_root.resolve()
    path = (inp.repo_root / model).resolve()
    if root not in path.parents or not path.is_file():
        inp.model_sources[model] = None
        return
    try:
        inp.model_sources[model] = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        inp.model_sources[model] = None
        return
    inp.model_copies[model] = f"source/{path.relative_to(root).as_posix()}"
    inp.files.append(InputFile(path, inp.model_copies[model]))


def _load_vectors(inp: Inputs) -> None:
    vdir = inp.results_dir / "vectors"
    files = sorted(vdir.glob("*.jsonl"))
    if not files:
        inp.missing.append("results/vectors/*.jsonl (conformance vectors)")
    seen = {}
    for f in files:
        header, vectors = None, []
        with f.open(encoding="utf-8") as fh:
            for lineno, line in enumerate(fh, 1):
                if not line.strip():
                    continue
                try:
                    obj = json.loads(line)
                except json.JSONDecodeError as exc:
                    raise PipelineError(f"{f}: line {lineno}: malformed JSON: {exc.msg}") from None
                _require(isinstance(obj, dict), f, f"line {lineno}", "must be an object")
                if obj.get("kind") == "header":
                    _require(header is None and not vectors, f, f"line {lineno}",
                             "the header must be the first line and appear once")
                    header = obj
                    continue
                _require(header is not None, f, f"line {lineno}", "vector before the header line")
                _require(isinstance(obj.get("id"), str) and obj["id"], f, f"line {lineno}",
                         "vector needs an 'id'")
                _require(obj["id"] not in seen, f, obj["id"],
                         f"duplicate vector id (also in {seen.get(obj['id'])})")
                seen[obj["id"]] = f.name
                vectors.append(obj)
        _require(header is not None, f, "line 1", "missing header line")
        rel = _rel(f, inp.results_dir)
        inp.vectors.append((rel, header, vectors))
        inp.files.append(InputFile(f, f"results/{rel}"))
    cfiles = sorted(vdir.glob("*.coverage.json"))
    if not cfiles:
        inp.missing.append("results/vectors/*.coverage.json (goal coverage)")
    for f in cfiles:
        data = _load_json(f, "goal coverage")
        _require(isinstance(data, dict) and isinstance(data.get("goals"), list), f, "goals",
                 "must be a list")
        for i, g in enumerate(data["goals"]):
            _require(isinstance(g, dict) and "id" in g and "status" in g, f, f"goals[{i}]",
                     "needs 'id' and 'status'")
        rel = _rel(f, inp.results_dir)
        inp.coverage.append((rel, data))
        inp.files.append(InputFile(f, f"results/{rel}"))


def _parse_junit(path: Path, rel: str) -> JUnitFile:
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
            cases = []
            for i, tc in enumerate(s.findall("testcase")):
                outcome = None
                for tag in ("failure", "error", "skipped"):
                    outcome = tc.find(tag)
                    if outcome is not None:
                        result = tag
                        break
                else:
                    result = "passed"
                if result == "error":
                    errors += 1
                props = {}
                for pr in tc.iter("property"):
                    if pr.get("name") is not None:
                        props.setdefault(pr.get("name"), pr.get("value", pr.text or ""))
                out = tc.find("system-out")
                cases.append(JUnitCase(
                    s.get("name", "unknown"), tc.get("classname", "unknown"),
                    tc.get("name", "unknown"), result, tc.get("time", ""), props,
                    message=(outcome.get("message", "") if outcome is not None else ""),
                    text=((outcome.text or "") if outcome is not None else ""),
                    system_out=((out.text or "") if out is not None else ""), index=i))
            if cases:
                nested = s is not ts
                suites.append(JUnitSuite(s.get("name", "unknown"), cases, nested,
                                         None if nested else k))
    view, why = _reports_view(path)
    return JUnitFile(rel, suites, errors, view, why)


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


def _load_tests(inp: Inputs) -> None:
    tdir = inp.results_dir / "tests"
    files = sorted(p for p in tdir.rglob("*.xml") if p.is_file()) if tdir.is_dir() else []
    if not files:
        inp.missing.append("results/tests/**/*.xml (unit and conformance test results)")
    for f in files:
        rel = _rel(f, inp.results_dir)
        inp.junit.append(_parse_junit(f, rel))
        inp.files.append(InputFile(f, f"results/{rel}"))


def _load_analysis(inp: Inputs) -> None:
    files = sorted((inp.results_dir / "analysis").glob("*.json"))
    if not files:
        inp.missing.append("results/analysis/*.json (offline analyses)")
    for f in files:
        data = _load_json(f, "analysis result")
        _require(isinstance(data, dict), f, "-", "top level must be an object")
        rel = _rel(f, inp.results_dir)
        inp.analysis.append((rel, data))
        inp.files.append(InputFile(f, f"results/{rel}"))


def _load_scenarios(inp: Inputs) -> None:
    """The line simulator's plots (scenarios/<name>.svg) and event logs (<name>.log.json):
    copied verbatim like every input; the plots are also embedded in the moving-block
    chapter (copied into the Sphinx sources, so they are hashed with the HTML)."""
    sdir = inp.results_dir / "scenarios"
    if not sdir.is_dir():
        return
    for f in sorted(p for p in sdir.iterdir() if p.is_file()):
        rel = _rel(f, inp.results_dir)
        if f.name.endswith(".svg"):
            head = f.read_bytes()[:4096].lstrip()
            _require(head.startswith(b"<?xml") or head.startswith(b"<svg"), f, "-",
                     "not an SVG image")
            inp.scenario_plots.append((f.name[:-len(".svg")], f))
        elif f.name.endswith(".log.json"):
            inp.scenario_logs[f.name[:-len(".log.json")]] = rel
        else:
            continue
        inp.files.append(InputFile(f, f"results/{rel}"))


def _load_proofs(inp: Inputs) -> None:
    """SMT proof results (proofs/<capability>.json, written by ``railproof_testgen
    proofs``): obligations with the verdict of each solver."""
    d = inp.results_dir / "proofs"
    for f in sorted(d.glob("*.json")) if d.is_dir() else []:
        data = _load_json(f, "proof result")
        _require(isinstance(data, dict) and isinstance(data.get("obligations"), list), f,
                 "obligations", "a proof result must hold a list 'obligations'")
        rel = _rel(f, inp.results_dir)
        inp.proofs.append((rel, data))
        inp.files.append(InputFile(f, f"results/{rel}"))
    for f in sorted(p for p in d.rglob("*.smt2") if p.is_file()) if d.is_dir() else []:
        inp.files.append(InputFile(f, f"results/{_rel(f, inp.results_dir)}"))


def _load_chapter_plots(inp: Inputs, subdir: str, plots: list) -> None:
    """Plots of a chapter's analyses (results/<subdir>/*.svg; braking: margins per line and
    train type and the speed-check design curve; odometry: the wheel-rail scenarios, error
    envelopes and margin comparisons), embedded in that chapter. Every other file of the
    directory (per-location or per-event JSON) is an input of the package too."""
    d = inp.results_dir / subdir
    for f in sorted(p for p in d.iterdir() if p.is_file()) if d.is_dir() else []:
        rel = _rel(f, inp.results_dir)
        if f.name.endswith(".svg"):
            head = f.read_bytes()[:4096].lstrip()
            _require(head.startswith(b"<?xml") or head.startswith(b"<svg"), f, "-",
                     "not an SVG image")
            plots.append((f.name[:-len(".svg")], f))
        inp.files.append(InputFile(f, f"results/{rel}"))


PEER_CHECK_NOTE = "design/lc.md"
ID_TOKEN = re.compile(r"\b(?:REQ|HAZ|ASM)-[A-Z0-9]+(?:-[0-9]+)?\b")


def _load_peer_check(inp: Inputs) -> None:
    """The peer cross-check of the level-crossing design note (§7): the first Markdown table
    of that section, one row per failure mode of the classic radio-based level-crossing case
    study with the railproof property, requirement or assumption that covers it."""
    note = inp.spec_dir / PEER_CHECK_NOTE
    if not note.is_file():
        return
    inp.files.append(InputFile(note, f"spec/{PEER_CHECK_NOTE}"))
    text = note.read_text(encoding="utf-8")
    start = re.search(r"^## 7\. Peer cross-check", text, re.M)
    if not start:
        return
    section = text[start.end():]
    end = re.search(r"^## ", section, re.M)
    section = section[:end.start()] if end else section
    rows = [ln.strip() for ln in section.splitlines() if ln.strip().startswith("|")]
    if len(rows) < 3:
        return
    cells = [[c.strip() for c in r.strip("|").split("|")] for r in rows]
    header, body = cells[0], [c for c in cells[2:] if any(c)]
    for i, c in enumerate(body):
        _require(len(c) == len(header), note, f"§7 table row {i + 1}",
                 f"{len(c)} cells where the header has {len(header)}")
    inp.peer_check = [dict(zip(header, c)) for c in body]


def _load_tool_versions(inp: Inputs, path: Path | None) -> None:
    if path is None:
        inp.missing.append("tool versions (--tool-versions)")
        return
    data = _load_json(path, "tool versions")
    _require(isinstance(data, dict), path, "-", "top level must be an object")
    inp.tool_versions = data
    inp.tool_versions_name = path.name
    inp.files.append(InputFile(path, f"tool-versions/{path.name}"))


def load_inputs(spec_dir: Path, results_dir: Path, repo_root: Path,
                tool_versions: Path | None = None) -> Inputs:
    inp = Inputs(Path(spec_dir), Path(results_dir), Path(repo_root))
    _load_spec(inp)
    if not inp.results_dir.is_dir():
        raise PipelineError(f"{inp.results_dir}: results directory not found")
    _load_trace(inp)
    _load_spin(inp)
    _load_vectors(inp)
    _load_tests(inp)
    _load_analysis(inp)
    _load_scenarios(inp)
    _load_proofs(inp)
    _load_chapter_plots(inp, "braking", inp.braking_plots)
    _load_chapter_plots(inp, "odometry", inp.odometry_plots)
    _load_chapter_plots(inp, "level_crossing", inp.crossing_plots)
    _load_peer_check(inp)
    _load_tool_versions(inp, Path(tool_versions) if tool_versions else None)
    return inp


# --------------------------------------------------------------------------------------
# page model: plain dicts handed to the Jinja templates


def _tokens(text: str) -> tuple:
    return tuple(t for t in re.split(r"[^A-Z0-9]+", text.upper()) if t)


def _contains_seq(hay: tuple, needle: tuple) -> bool:
    n = len(needle)
    return n > 0 and any(hay[i:i + n] == needle for i in range(len(hay) - n + 1))


def _case_keys(c: JUnitCase) -> set:
    keys = {f"{c.classname}.{c.name}", f"{c.classname}::{c.name}", f"{c.suite}.{c.name}"}
    if "." in c.classname:   # pytest: tests.test_x + test_y  <->  tests/test_x.py::test_y
        keys.add(c.classname.replace(".", "/") + ".py::" + c.name)
    return keys


def _unit_match(test: str, keys: set, name: str) -> bool:
    if test in keys or test == name:
        return True
    return any(test.endswith("/" + k) for k in keys if "::" in k)


_RESULT_RANK = {"passed": 0, "skipped": 1, "failure": 2, "error": 3}
_ASSERT_TAG = re.compile(r"^\s*//+\s*@assert\s+(\S+)\s+(.*?)\s*:\s*(.*?)\s*$")
_REQ_ID = re.compile(r"\bREQ-[A-Z]+-\d+\b")
_PROP_SHOWN = {"name", "requirements", "verdict", "states_stored", "depth", "errors", "time_s",
               "memory_mb", "text", "configuration", "command", "counterexample", "transitions",
               "incomplete"}
_MUT_SHOWN = {"name", "expect", "verdict", "property", "text", "counterexample"}
_CASE_SPLIT = re.compile(r"^(?P<name>[^\[]+)(?:$|\[(?P<param>.*)\]$)", re.DOTALL)


def model_assertions(text: str) -> dict:
    """Named assertions of a Promela model: ``// @assert <label> <REQ ids> : text`` on the
    line before an ``assert(...)``. Returns {label: {"requirements", "text", "line"}}."""
    out = {}
    for n, line in enumerate(text.splitlines(), 1):
        m = _ASSERT_TAG.match(line)
        if m and m.group(1) not in out:
            out[m.group(1)] = {"requirements": _REQ_ID.findall(m.group(2)),
                               "text": m.group(3), "line": n}
    return out


def _pan_checks_assertions(command: str) -> bool:
    """pan checks every assert() in every run unless started with -A."""
    return "-A" not in command.replace("&&", " ").split()


def _own_need(kind: str, title: str, fields: dict, note: str, links=(), verifies=(),
              replays=(), exact=(), blocks=(), style=None) -> str:
    """The JSON content of an ``rp-test-need`` directive (evidence/_ext): a need of
    sphinx-test-reports' type ``kind`` built from this module's parse of the XML. JSON with
    ensure_ascii has no character that could end or re-indent a reStructuredText line, so
    any test name passes through unchanged."""
    obj = {"type": kind, "title": title, "fields": fields, "note": note,
           "links": list(links), "verifies": list(verifies), "replays": list(replays),
           "exact": [list(e) for e in exact], "blocks": [list(b) for b in blocks if b[1].strip()],
           "style": style}
    return json.dumps(obj, ensure_ascii=True, sort_keys=True, indent=1)


def _time_text(t: str) -> str:
    try:
        return str(float(t)) if t else "0.0"
    except ValueError:
        return display_text(t)


class Model:
    """Everything the templates show, computed once from the inputs."""

    def __init__(self, inp: Inputs, command: str):
        self.inp = inp
        self.command = command
        self.need_ids: set = set()
        self.problems: list = []       # reasons for a FAIL verdict
        self.incomplete: list = list(inp.missing)
        self._spec()
        self._trace()
        self._spin()
        self._vectors()
        self._coverage()
        self._tests()
        self._conformance()
        self._analysis()
        self._requirement_links()
        self._moving_block()
        self._braking()
        self._readhesion()
        self._level_crossing()
        self._versions()
        self._verdict()

    # -- spec -----------------------------------------------------------------------------
    def _claim(self, nid: str, what: str) -> str:
        if nid in self.need_ids:
            raise PipelineError(f"two inputs map to the same need id {nid} ({what})")
        self.need_ids.add(nid)
        return nid

    def _readable(self, *parts: str, limit: int = 72) -> str:
        """A readable need id for a test item; long names keep a hash suffix, and a clash
        with an earlier id gets _2, _3 ... (inputs are processed in a fixed order)."""
        nid = need_id(*parts, upper=False)
        if len(nid) > limit:
            digest = hashlib.sha256("\0".join(parts).encode()).hexdigest()[:8].upper()
            nid = nid[:limit - 9].rstrip("_-") + "_" + digest
        base, n = nid, 1
        while nid in self.need_ids:
            n += 1
            nid = f"{base}_{n}"
        self.need_ids.add(nid)
        return nid

    def _spec(self):
        inp = self.inp
        self.hazard_ids = {h["id"] for h in inp.hazards}
        self.asm_ids = {a["id"] for a in inp.assumptions}
        self.req_ids = {r["id"] for r in inp.requirements}
        self.hazards = []
        for h in inp.hazards:
            self.hazards.append({"id": self._claim(h["id"], "hazard"), "title": h.get("title", h["id"]),
                                 "text": h.get("text", ""), "severity": h.get("severity", ""),
                                 "source": "; ".join(map(str, h.get("source") or []))})
        self.assumptions = []
        for a in inp.assumptions:
            self.assumptions.append({"id": self._claim(a["id"], "assumption"),
                                     "title": a.get("title", a["id"]), "text": a.get("text", ""),
                                     "source": "; ".join(map(str, a.get("source") or []))})
        self.parameters = []
        for area in sorted(inp.parameters):
            d = inp.parameters[area]
            self.parameters.append({
                "area": area, "file": Path(d["file"]).name,
                "parameters": [{"id": k, "value": fmt_value(e["value"]), "unit": e.get("unit", ""),
                                "source": e.get("source", ""),
                                "requirements": ", ".join(e.get("requirements") or [])}
                               for k, e in d["parameters"].items()],
                "bounds": [{"id": k, "value": fmt_value(e["value"]), "rationale": e.get("rationale", "")}
                           for k, e in d["model_bounds"].items()]})

    # -- trace ----------------------------------------------------------------------------
    def _trace(self):
        t = self.inp.trace
        self.trace_by_id = {r["id"]: r for r in t.get("requirements", [])}
        self.trace_errors = [str(e) for e in t.get("errors") or []]
        self.trace_warnings = [str(w) for w in t.get("warnings") or []]
        self.trace_summary = [(str(k), fmt_value(v)) for k, v in (t.get("summary") or {}).items()]
        self.trace_unknown = sorted(set(self.trace_by_id) - self.req_ids)
        if self.trace_errors:
            self.problems.append(f"traceability check reported {len(self.trace_errors)} error(s)")
        for rid in self.trace_unknown:
            self.problems.append(f"trace.json names {rid}, which is not in the specification")

    # -- model checking -------------------------------------------------------------------
    def _trace_assertions(self, model: str) -> dict:
        """{label: {requirement ids}} of the ``assert:<label>`` model links in trace.json."""
        out: dict = {}
        for rid, r in sorted(self.trace_by_id.items()):
            for m in (r.get("links") or {}).get("model") or []:
                if isinstance(m, dict) and str(m.get("property", "")).startswith("assert:") \
                        and m.get("model", model) == model:
                    out.setdefault(str(m["property"])[7:], set()).add(rid)
        return out

    def _spin(self):
        self.models = []
        self.prop_by_name = {}
        for rel, d in self.inp.spin:
            stem = Path(rel).stem
            model = str(d.get("model", stem))
            sha = str(d.get("model_sha256", ""))
            src = self.inp.repo_root / model
            if not sha:
                src_check = "no model hash in the result"
            elif src.is_file():
                src_check = ("matches the source tree" if sha256_file(src) == sha
                             else "DIFFERS from the source tree")
            else:
                src_check = "model file not in the source tree"
            props = []
            for p in d.get("properties", []):
                # The same property checked in another configuration of the model (a
                # variant) gets the configuration appended to its id.
                config = str(p.get("configuration") or "")
                nid = self._readable("PROP", p["name"]) if need_id("PROP", p["name"], upper=False) \
                    not in self.need_ids else self._readable("PROP", p["name"], config or stem)
                reqs = [r for r in p.get("requirements") or []]
                links = [r for r in reqs if r in self.req_ids]
                unknown = [r for r in reqs if r not in self.req_ids]
                verdict = str(p["verdict"])
                for r in unknown:
                    self.problems.append(f"model property {p['name']} names unknown requirement {r}")
                if verdict != "verified":
                    where = f"{model}, configuration {config}" if config else model
                    self.problems.append(f"model property {p['name']} ({where}): {verdict}")
                incomplete = p.get("incomplete") or []
                props.append({"id": nid, "name": p["name"], "kind": "ltl", "verdict": verdict,
                              "text": str(p.get("text") or ""),
                              "configuration": str(p.get("configuration") or ""),
                              "states": fmt_value(p.get("states_stored")),
                              "transitions": fmt_value(p.get("transitions")),
                              "depth": fmt_value(p.get("depth")),
                              "errors": fmt_value(p.get("errors")),
                              "time_s": fmt_value(p.get("time_s")),
                              "memory_mb": fmt_value(p.get("memory_mb")),
                              "command": str(p.get("command") or ""),
                              "counterexample": str(p.get("counterexample") or ""),
                              "incomplete": fmt_value(incomplete) if incomplete else "",
                              "links": links, "unknown": unknown,
                              "extra": sorted((k, fmt_value(v)) for k, v in p.items()
                                              if k not in _PROP_SHOWN)})
                self.prop_by_name.setdefault(p["name"], nid)
                self.prop_by_name[(model, p["name"])] = nid
            runs = list(d.get("properties", []))
            mutant_list = [m for m in d.get("mutants", [])]
            assertions = self._assertions(model, stem, runs, mutant_list, props)
            by_name = {p["name"]: p["id"] for p in props + assertions}
            mutants = []
            for m in mutant_list:
                nid = self._readable("MUT", m["name"]) if need_id("MUT", m["name"], upper=False) \
                    not in self.need_ids else self._readable("MUT", stem, m["name"])
                expect = str(m.get("expect", "rejected"))
                verdict = str(m["verdict"])
                if verdict != expect:
                    self.problems.append(f"mutant {m['name']} ({model}): {verdict}, expected {expect}")
                prop = str(m.get("property") or "")
                mutants.append({"id": nid, "name": m["name"], "expect": expect, "verdict": verdict,
                                "property": prop, "target": by_name.get(prop),
                                "text": str(m.get("text") or ""),
                                "counterexample": str(m.get("counterexample") or ""),
                                "extra": sorted((k, fmt_value(v)) for k, v in m.items()
                                                if k not in _MUT_SHOWN)})
            bounds = [(str(k), fmt_value(v)) for k, v in (d.get("bounds") or {}).items()]
            other = [(str(k), fmt_value(v)) for k, v in d.items()
                     if k not in ("model", "model_sha256", "spin_version", "bounds", "properties",
                                  "mutants")]
            source = self.inp.model_copies.get(model)
            commands = []
            for p in props:
                if p["command"] and p["command"] not in commands:
                    commands.append(p["command"])
            self.models.append({"rel": rel, "stem": stem, "model": model, "sha": sha,
                                "src_check": src_check, "spin_version": str(d.get("spin_version", "n/a")),
                                "bounds": bounds, "other": other, "properties": props,
                                "assertions": assertions, "mutants": mutants, "source": source,
                                "commands": commands,
                                "verified": sum(p["verdict"] == "verified" for p in props),
                                "assertions_verified": sum(a["verdict"] == "verified" for a in assertions),
                                "rejected": sum(m["verdict"] == m["expect"] for m in mutants)})
            if src_check.startswith("DIFFERS"):
                self.problems.append(f"{model}: model hash in {rel} differs from the source tree")

    def _assertions(self, model: str, stem: str, runs: list, mutants: list, props: list) -> list:
        """Needs for the model's named assertions (``assert:<label>``) that the result file
        does not list as properties of their own. pan checks every assert() of the model
        in every verification run (unless started with -A), so an assertion is verified
        when every run of the model completed without an error."""
        src = self.inp.model_sources.get(model)
        annotated = model_assertions(src) if src else {}
        from_trace = self._trace_assertions(model)
        named = set(annotated) | set(from_trace)
        named |= {str(m.get("property"))[7:] for m in mutants
                  if str(m.get("property") or "").startswith("assert:")}
        listed = {p["name"][7:] for p in props if p["name"].startswith("assert:")}
        checking = [p for p in runs if _pan_checks_assertions(str(p.get("command") or ""))]
        # properties verified together share one search (one configuration and command)
        n_runs = len({(str(p.get("configuration") or "default"), str(p.get("command") or ""))
                      for p in checking})
        out = []
        for label in sorted(named - listed):
            name = f"assert:{label}"
            ann = annotated.get(label)
            reqs = list(ann["requirements"]) if ann else sorted(from_trace.get(label, ()))
            killers = [m["name"] for m in mutants if m.get("property") == name
                       and m.get("verdict") == m.get("expect", "rejected") == "rejected"]
            bad = [p for p in checking
                   if str(p.get("verdict")) != "verified" or (p.get("errors") or 0) != 0]
            configs = sorted({str(p.get("configuration") or "default") for p in checking})
            if not checking:
                verdict = "not checked"
                basis = ("the result file lists no verification run of this model that checks "
                         "assertions")
            elif bad:
                verdict = "not established"
                basis = (f"{len(bad)} of the {len(checking)} property results of this model did "
                         f"not complete without an error (first: {bad[0].get('name')})")
            else:
                verdict = "verified"
                basis = (f"pan checks every assert() of the model in every run not started with "
                         f"-A; all {n_runs} verification runs of this model "
                         f"(configurations: {', '.join(configs)}) searched their whole state "
                         "space without an error")
            if killers:
                basis += (f"; mutant {', '.join(killers)}, which breaks this assertion, was "
                          "rejected by a run of the same kind, so the check is active")
            nid = self._readable("ASSERT", label) if need_id("ASSERT", label, upper=False) \
                not in self.need_ids else self._readable("ASSERT", stem, label)
            for r in reqs:
                if r not in self.req_ids:
                    self.problems.append(f"model assertion {label} names unknown requirement {r}")
            if verdict != "verified":
                self.problems.append(f"model assertion {label} ({model}): {verdict}")
            origin = (f"annotated in {model} line {ann['line']}" if ann else
                      "named by a mutant or by trace.json; the model source is not in this package")
            out.append({"id": nid, "name": name, "label": label, "kind": "assertion",
                        "verdict": verdict, "text": ann["text"] if ann else "", "basis": basis,
                        "states": f"in {n_runs} runs" if checking else "n/a",
                        "origin": origin, "runs": n_runs, "configurations": ", ".join(configs),
                        "links": [r for r in reqs if r in self.req_ids],
                        "unknown": [r for r in reqs if r not in self.req_ids]})
            self.prop_by_name.setdefault(name, nid)
            self.prop_by_name[(model, name)] = nid
        return out

    # -- vectors --------------------------------------------------------------------------
    def _vectors(self):
        self.vector_files = []
        self.vector_by_id = {}
        self.vector_items = {}     # need id -> item
        for rel, header, vectors in self.inp.vectors:
            stem = Path(rel).name[:-len(".jsonl")]
            by_req: dict = {}
            items = []
            for v in vectors:
                nid = self._claim(need_id(v["id"], upper=False), f"vector {v['id']}")
                reqs = [str(r) for r in v.get("requirements") or []]
                steps = v.get("steps") or []
                if v.get("goal"):
                    title = str(v["goal"])
                elif v.get("seed") is not None:
                    title = f"{v.get('kind') or 'random'} walk, seed {fmt_value(v['seed'])}"
                else:
                    title = str(v["id"])
                item = {"id": nid, "orig": v["id"], "goal": str(v.get("goal") or ""),
                        "title": title,
                        "kind": str(v.get("kind") or ""), "role": str(v.get("role") or ""),
                        "links": [r for r in reqs if r in self.req_ids],
                        "unknown": [r for r in reqs if r not in self.req_ids],
                        "nsteps": len(steps), "steps": [safe_json_line(s) for s in steps],
                        "conformance": "not replayed", "cases": [],
                        "extra": sorted((k, fmt_value(x)) for k, x in v.items()
                                        if k not in ("id", "requirements", "goal", "steps",
                                                     "kind", "role"))}
                items.append(item)
                self.vector_by_id[v["id"]] = nid
                self.vector_items[nid] = item
                home = reqs[0] if reqs else "(no requirement)"
                by_req.setdefault(home, []).append(item)
                for r in item["unknown"]:
                    self.problems.append(f"vector {v['id']} names unknown requirement {r}")
            counts: dict = {}
            for it in items:
                for r in it["links"] + it["unknown"]:
                    counts[r] = counts.get(r, 0) + 1
            hdr = [(k, fmt_value(x)) for k, x in header.items()
                   if k not in ("kind", "parameters", "unit_scales")]
            self.vector_files.append({
                "rel": rel, "stem": stem, "page": f"vectors_{need_id(stem).lower()}",
                "header": hdr, "items": items,
                "unit_scales": [(k, fmt_value(x)) for k, x in (header.get("unit_scales") or {}).items()],
                "parameters": [(k, fmt_value(x)) for k, x in (header.get("parameters") or {}).items()],
                "count": len(items), "steps": sum(i["nsteps"] for i in items),
                "groups": [(r, by_req[r]) for r in sorted(by_req)],
                "per_req": sorted(counts.items())})
        if self.inp.vectors and not any(f["count"] for f in self.vector_files):
            self.problems.append("the vector files hold no vectors")

    def _coverage(self):
        self.coverage = []
        self.goals_by_req: dict = {}
        for rel, d in self.inp.coverage:
            goals = []
            for g in d["goals"]:
                status = str(g["status"])
                vecs = g.get("vectors")
                if vecs is None:          # older format: one "vector" per goal
                    vecs = [g["vector"]] if g.get("vector") else []
                elif not isinstance(vecs, list):
                    vecs = [vecs]
                vecs = [str(v) for v in vecs if v]
                just = g.get("justification")
                ok = (status == "reached" and vecs) or (status == "unreachable" and just)
                if not ok:
                    self.problems.append(f"goal {g['id']} ({rel}): {status} without "
                                         f"{'vector' if status == 'reached' else 'justification'}")
                for v in vecs:
                    if v not in self.vector_by_id:
                        self.problems.append(f"goal {g['id']} ({rel}) names vector {v}, which is "
                                             "not in the vector files")
                jentry = self.inp.justifications.get(str(just)) if just else None
                reqs = [str(r) for r in g.get("requirements") or []]
                goal = {"id": str(g["id"]), "label": str(g.get("label", "")),
                        "requirements": ", ".join(reqs), "reqs": reqs,
                        "status": status, "vectors": vecs,
                        "vector_needs": [self.vector_by_id[v] for v in vecs if v in self.vector_by_id],
                        "justification": str(just) if just else "",
                        "justification_text": " ".join(str(jentry.get("text", "")).split())
                        if jentry else "",
                        "states_searched": fmt_value(g["states_searched"])
                        if g.get("states_searched") is not None else "",
                        "rel": rel}
                goals.append(goal)
                for nid in goal["vector_needs"]:
                    if goal["label"]:
                        self.vector_items[nid]["title"] = f"{goal['id']}: {goal['label']}"
                for r in reqs:
                    self.goals_by_req.setdefault(r, []).append(goal)
            reached = d.get("reached", sum(g["status"] == "reached" for g in goals))
            labelled = d.get("labelled", len(goals))
            extra = [(k, fmt_value(v)) for k, v in d.items() if k not in ("goals", "reached", "labelled")]
            self.coverage.append({"rel": rel, "goals": goals, "reached": reached, "labelled": labelled,
                                  "unreachable": [g for g in goals if g["status"] == "unreachable"],
                                  "extra": extra})

    # -- tests ----------------------------------------------------------------------------
    @staticmethod
    def _suite_why(jf: JUnitFile, s: JUnitSuite, file_why: str) -> str:
        """Why sphinx-test-reports cannot render this suite's need exactly ("" if it can):
        its test-suite directive takes the first top-level suite of that name, and its
        test-case directive searches that suite's cases."""
        if file_why:
            return file_why
        if s.nested:
            return "a nested suite (sphinx-test-reports 1.3.1 looks suites up at the top level only)"
        if not plain_option(s.name):
            return ("its suite name cannot be passed unchanged to sphinx-test-reports as a "
                    "one-line directive option")
        view = jf.reports_view or []
        first = next((j for j, v in enumerate(view) if v.get("name") == s.name), None)
        if first != s.top_index:
            return "an earlier top-level suite of the file has the same name"
        theirs = [(c.get("classname"), c.get("name")) for c in view[first].get("testcases", [])]
        if theirs != [(c.classname, c.name) for c in s.cases]:
            return "sphinx-test-reports reads a different list of cases for this suite"
        return ""

    @staticmethod
    def _case_why(suite_why: str, vcases: list, c: JUnitCase) -> str:
        """Why sphinx-test-reports cannot render this case exactly ("" if it can)."""
        if suite_why:
            return suite_why
        if not (plain_option(c.name) and plain_option(c.classname)):
            return ("its name cannot be passed unchanged to sphinx-test-reports as a one-line "
                    "directive option")
        first = next((j for j, v in enumerate(vcases)
                      if v.get("name") == c.name and v.get("classname") == c.classname), None)
        if first != c.index:
            return ("an earlier case of the suite has the same class and name (sphinx-test-reports "
                    "would show that one)")
        theirs = vcases[c.index]
        if theirs.get("result") != c.result:
            return (f"sphinx-test-reports 1.3.1 would show it as {theirs.get('result')} "
                    f"(it does not read a JUnit <{c.result}> element)")
        for key in ("text", "message", "system-out"):
            t = theirs.get(key)
            if t and not t.strip():
                return f"its {key} is blank (sphinx-test-reports would emit an empty literal block)"
        return ""

    def _replayed(self, c: JUnitCase, title: str, rel: str, vec_tokens: list) -> list:
        """The vector needs a test case replays: its ``vector_id`` property (written by the
        conformance runner) or, for runners that write none, the vector id spelled inside
        the test name (``TG-TRAP-017`` in ``Replays/TG_TRAP_017``)."""
        vid = c.properties.get("vector_id")
        if vid is not None:
            nid = self.vector_by_id.get(vid)
            if nid is None:
                self.problems.append(f"test {title} ({rel}) replays vector {vid}, which is not in "
                                     "the vector files")
                return []
            return [nid]
        toks = _tokens(f"{c.classname} {c.name}")
        hits = [(vt, nid) for vt, nid in vec_tokens if _contains_seq(toks, vt)]
        # MB-TRAP-G1 is spelled inside MB_TRAP_G1_2 too: keep only the most specific ids
        return sorted({nid for vt, nid in hits
                       if not any(len(o) > len(vt) and _contains_seq(o, vt) for o, _ in hits)})

    def _tests(self):
        unit_map = []   # (test string, requirement)
        for rid, r in self.trace_by_id.items():
            for u in (r.get("links") or {}).get("unit") or []:
                if isinstance(u, dict) and u.get("test"):
                    unit_map.append((str(u["test"]), rid))
        vec_tokens = [(_tokens(vid), nid) for vid, nid in self.vector_by_id.items()]
        self.case_by_test = {}
        self.replays_by_vector: dict = {}
        self.test_files = []
        self.own_rendered = 0
        totals = {"passed": 0, "failure": 0, "error": 0, "skipped": 0}
        for jf in self.inp.junit:
            fid = self._readable("TF", jf.rel.removeprefix("tests/").removesuffix(".xml"))
            if jf.reports_view is None:
                file_why = jf.reports_error
            elif not plain_option(jf.rel):
                file_why = ("its path cannot be passed unchanged to sphinx-test-reports as a "
                            "one-line directive option")
            else:
                file_why = ""
            suites = []
            counts = {"passed": 0, "failure": 0, "error": 0, "skipped": 0}
            for s in jf.suites:
                sid = self._readable("TS", s.name)
                s_why = self._suite_why(jf, s, file_why)
                vcases = [] if s_why else (jf.reports_view or [])[s.top_index].get("testcases", [])
                scounts = {"passed": 0, "failure": 0, "error": 0, "skipped": 0}
                items = []
                for c in s.cases:
                    cid = self._readable("TC", c.classname, c.name)
                    title = display_text(f"{c.classname}.{c.name}")
                    keys = _case_keys(c)
                    reqs = sorted({rid for test, rid in unit_map if _unit_match(test, keys, c.name)})
                    vecs = self._replayed(c, title, jf.rel, vec_tokens)
                    counts[c.result] += 1
                    scounts[c.result] += 1
                    if c.result in ("failure", "error"):
                        self.problems.append(f"test {title} ({jf.rel}): {c.result}")
                    for v in vecs:
                        self.replays_by_vector.setdefault(v, []).append((cid, c.result))
                    why = self._case_why(s_why, vcases, c)
                    item = {"id": cid, "suite": s.name, "classname": c.classname, "name": c.name,
                            "title": title, "result": c.result, "verifies": reqs, "vectors": vecs,
                            "own": ""}
                    if why:
                        self.own_rendered += 1
                        m = _CASE_SPLIT.match(c.name)
                        exact = [(k, v) for k, v in (("name", c.name), ("classname", c.classname),
                                                     ("suite", s.name))
                                 if display_text(v) != v]
                        item["own"] = _own_need(
                            "testcase", title,
                            {"file": display_text(jf.rel), "suite": display_text(s.name),
                             "case": display_text(c.name),
                             "case_name": display_text(m.group("name") if m else c.name),
                             "case_parameter": display_text(m.group("param"))
                             if m and m.group("param") else "",
                             "classname": display_text(c.classname), "result": c.result,
                             "time": _time_text(c.time)},
                            f"Rendered from the JUnit XML by the evidence build, not by "
                            f"sphinx-test-reports: {why}.",
                            links=[sid], verifies=reqs, replays=vecs, exact=exact,
                            blocks=[("Message", c.message), ("Text", c.text),
                                    ("System-out", c.system_out)],
                            style=f"tr_{c.result}")
                    items.append(item)
                    for k in keys | {c.name}:
                        self.case_by_test.setdefault(k, cid)
                sitem = {"id": sid, "name": s.name, "title": display_text(s.name), "cases": items,
                         "nested": s.nested, "own": ""}
                if s_why:
                    sitem["own"] = _own_need(
                        "testsuite", display_text(s.name),
                        {"file": display_text(jf.rel), "suite": display_text(s.name),
                         "cases": len(items), "passed": scounts["passed"],
                         "skipped": scounts["skipped"], "failed": scounts["failure"],
                         "errors": scounts["error"]},
                        f"Rendered from the JUnit XML by the evidence build, not by "
                        f"sphinx-test-reports: {s_why}.", links=[fid],
                        exact=[("suite", s.name)] if display_text(s.name) != s.name else [])
                suites.append(sitem)
            for k in totals:
                totals[k] += counts[k]
            ncases = sum(len(s["cases"]) for s in suites)
            fitem = {"id": fid, "rel": jf.rel, "suites": suites, "counts": counts,
                     "cases": ncases, "error_elements": jf.error_elements, "own": ""}
            if file_why:
                fitem["own"] = _own_need(
                    "testfile", display_text(jf.rel),
                    {"file": display_text(jf.rel), "suites": len(suites), "cases": ncases,
                     "passed": counts["passed"], "skipped": counts["skipped"],
                     "failed": counts["failure"], "errors": counts["error"]},
                    f"Rendered from the JUnit XML by the evidence build, not by "
                    f"sphinx-test-reports: {file_why}.")
            self.test_files.append(fitem)
        self.test_totals = totals

    def _conformance(self):
        """Each vector's replay result: the worst result of the test cases replaying it."""
        stats = {"vectors": 0, "passed": 0, "failed": 0, "skipped": 0, "not_replayed": 0}
        missing, skipped = [], []
        for nid, item in self.vector_items.items():
            rs = self.replays_by_vector.get(nid, [])
            item["cases"] = [cid for cid, _ in rs]
            stats["vectors"] += 1
            if not rs:
                item["conformance"] = "not replayed"
                stats["not_replayed"] += 1
                missing.append(item["orig"])
                continue
            worst = max((r for _, r in rs), key=lambda r: _RESULT_RANK.get(r, 3))
            item["conformance"] = worst
            if worst == "passed":
                stats["passed"] += 1
            elif worst == "skipped":
                stats["skipped"] += 1
                skipped.append(item["orig"])
            else:
                stats["failed"] += 1
        self.conformance = stats
        if not self.vector_items or not self.inp.junit:
            return
        if not self.replays_by_vector:
            self.incomplete.append("conformance results: no JUnit test case replays a vector")
            return
        if missing:
            self.problems.append(f"{len(missing)} vector(s) not replayed by any conformance test "
                                 f"case (first: {missing[0]})")
        if skipped:
            self.problems.append(f"{len(skipped)} vector(s) whose conformance test case was "
                                 f"skipped (first: {skipped[0]})")

    # -- analysis -------------------------------------------------------------------------
    def _analysis(self):
        """One need per analysis result. Nested objects are flattened into dotted names
        (``channel.loss_probability``); a list of records, or an object whose values are all
        records (``checks``: one record per requirement), is a table with flattened columns.
        A record with ``meets_target: false`` or ``result: FAIL`` (at the top level or in a
        table) fails the package."""
        self.analyses = []
        for rel, d in self.inp.analysis:
            stem = Path(rel).stem
            nid = self._claim(need_id("RES", stem), f"analysis {rel}")
            reqs = [str(r) for r in d.get("requirements") or []]
            scalars, tables, fails = [], [], []
            for k, v in d.items():
                if k == "requirements":
                    continue
                records = None
                if isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
                    records = [(None, x) for x in v]
                elif isinstance(v, dict) and v and all(isinstance(x, dict) for x in v.values()):
                    records = list(v.items())
                if records is not None:
                    flat = [_flatten(row) for _, row in records]
                    cols = [] if records[0][0] is None else ["key"]
                    for row in flat:
                        for c in row:
                            if c not in cols:
                                cols.append(c)
                    rows = [[fmt_value(key if c == "key" and key is not None else row.get(c))
                             for c in cols] for (key, _), row in zip(records, flat)]
                    tables.append({"name": k, "columns": cols, "rows": rows})
                    for i, ((key, _), row) in enumerate(zip(records, flat)):
                        if row.get("meets_target") is False or str(row.get("result")) == "FAIL":
                            fails.append(f"{k}[{i if key is None else key}]")
                elif isinstance(v, dict):
                    for fk, fv in _flatten(v, k).items():
                        scalars.append((fk, fmt_value(fv)))
                else:
                    scalars.append((k, fmt_value(v) if v != [] else "none"))
                    if (k == "meets_target" and v is False) or (k == "result" and v == "FAIL"):
                        fails.append(k)
            for r in reqs:
                if r not in self.req_ids:
                    self.problems.append(f"analysis {rel} names unknown requirement {r}")
            outcome = "fail" if fails else "pass"
            if fails:
                self.problems.append(f"analysis {rel}: target not met in {', '.join(fails)}")
            self.analyses.append({"id": nid, "rel": rel, "stem": stem,
                                  "title": stem.replace("_", " "),
                                  "schema": str(d.get("schema") or ""),
                                  "links": [r for r in reqs if r in self.req_ids],
                                  "unknown": [r for r in reqs if r not in self.req_ids],
                                  "scalars": scalars, "tables": tables, "outcome": outcome,
                                  "fails": fails, "data": d})

    # -- requirements with their trace ----------------------------------------------------
    def _requirement_links(self):
        self.requirements = []
        self.areas = []
        by_file: dict = {}
        all_props = [p for mo in self.models for p in mo["properties"] + mo["assertions"]]
        all_mutants = [mu for mo in self.models for mu in mo["mutants"]]
        for r in self.inp.requirements:
            rid = r["id"]
            self._claim(rid, "requirement")
            t = self.trace_by_id.get(rid)
            links = (t or {}).get("links") or {}
            status = str(t.get("status", "error")) if t else "untraced"
            problems = [str(p) for p in (t or {}).get("problems") or []]
            if not t:
                problems.append("no entry in trace.json")
            if status != "ok":
                self.problems.append(f"{rid}: trace status {status}")
            model = []
            for m in links.get("model") or []:
                if isinstance(m, dict):
                    name = str(m.get("property", ""))
                    nid = self.prop_by_name.get((m.get("model"), name)) or self.prop_by_name.get(name)
                    model.append({"name": name, "verdict": str(m.get("verdict", "")), "need": nid,
                                  "model": str(m.get("model", ""))})
            vecs = [str(v) for v in links.get("vectors") or []]
            unit = []
            for u in links.get("unit") or []:
                if isinstance(u, dict):
                    test = str(u.get("test", ""))
                    unit.append({"test": test, "file": str(u.get("file", "")),
                                 "need": self.case_by_test.get(test)})
            code = [{"file": str(c.get("file", "")), "unit": str(c.get("unit", ""))}
                    for c in links.get("code") or [] if isinstance(c, dict)]
            analysis = [fmt_value(a) for a in links.get("analysis") or []]
            proof = [fmt_value(p) for p in links.get("proof") or []]
            goals = [fmt_value(g) for g in links.get("goals") or []]
            counts = (f"model {len(model)}, goals {len(goals)}, vectors {len(vecs)}, unit {len(unit)}, "
                      f"code {len(code)}, analysis {len(analysis)}, proof {len(proof)}")
            src = [str(s) for s in r.get("source") or []]
            asms = sorted({m for s in src for m in re.findall(r"ASM(?:-[A-Z]+)?-\d+", s)}
                          | {m for m in re.findall(r"ASM(?:-[A-Z]+)?-\d+", str(r.get("text", "")))})
            # evidence resolved from the results themselves (the tables of the page)
            props = [p for p in all_props if rid in p["links"]]
            prop_ids = {p["id"] for p in props}
            mutants = [mu for mu in all_mutants if mu["target"] in prop_ids]
            vitems = [it for it in self.vector_items.values() if rid in it["links"]]
            vstat = {"total": len(vitems),
                     "passed": sum(it["conformance"] == "passed" for it in vitems),
                     "failed": sum(it["conformance"] in ("failure", "error") for it in vitems),
                     "skipped": sum(it["conformance"] == "skipped" for it in vitems),
                     "not_replayed": sum(it["conformance"] == "not replayed" for it in vitems)}
            item = {
                "id": rid, "title": r.get("title", rid), "text": r.get("text", ""),
                "page": f"requirements/{rid}",
                "sil": fmt_value(r.get("sil")), "source": "; ".join(src),
                "verification": ", ".join(map(str, r.get("verification") or [])),
                "defence": r.get("defence", ""), "threat": r.get("threat", ""),
                "hazards": [h for h in r.get("hazards") or [] if h in self.hazard_ids],
                "hazards_unknown": [h for h in r.get("hazards") or [] if h not in self.hazard_ids],
                "assumptions": [a for a in asms if a in self.asm_ids],
                "status": status, "problems": problems, "counts": counts,
                "model": model, "model_unresolved": [m for m in model if not m["need"]],
                "props": props, "mutants": mutants, "goals": goals,
                "goal_rows": self.goals_by_req.get(rid, []),
                "vectors": [{"id": v, "need": self.vector_by_id.get(v)} for v in vecs],
                "vectors_unresolved": [v for v in vecs if v not in self.vector_by_id],
                "vector_stats": vstat,
                "unit": unit, "unit_missing": [u for u in unit if not u["need"]],
                "code": code, "analysis": analysis, "proof": proof,
            }
            self.requirements.append(item)
            by_file.setdefault((r["_file"], r.get("_area", "")), []).append(item)
        for (fname, area), items in by_file.items():
            self.areas.append({"file": fname, "area": area, "requirements": items})
        self.req_ok = sum(r["status"] == "ok" for r in self.requirements)

    # -- moving-block chapter -------------------------------------------------------------
    def _moving_block(self):
        """The data of the moving-block chapter, gathered from the generic results: the
        REQ-MB requirements, the moving_block model's runs per configuration, its goal
        coverage, vector files and conformance test file, and the line simulator's
        scenario summaries, gap sweep and plots."""
        cfg_rank = {c: i for i, c in enumerate(MB_CONFIGURATIONS)}
        mb = {"requirements": [r for r in self.requirements if r["id"].startswith("REQ-MB-")]}
        model = next((mo for mo in self.models if mo["stem"] == "moving_block"
                      or mo["model"].endswith("moving_block.pml")), None)
        mb["model"] = model
        runs, configs, names = [], [], []
        if model:
            for p in model["properties"]:
                cfg = p["configuration"] or "default"
                if cfg not in configs:
                    configs.append(cfg)
                if p["name"] not in names:
                    names.append(p["name"])
            order = {n: i for i, n in enumerate(names)}
            runs = sorted(model["properties"], key=lambda p: (
                order[p["name"]], cfg_rank.get(p["configuration"] or "default", len(cfg_rank)),
                p["configuration"]))
            for mu in model["mutants"]:
                cfg = dict(mu["extra"]).get("configuration", "default")
                mu["configuration"] = cfg
                if cfg not in configs:
                    configs.append(cfg)
        configs.sort(key=lambda c: (cfg_rank.get(c, len(cfg_rank)), c))
        mb["runs"] = runs
        mb["properties"] = names
        mb["configurations"] = [(c, MB_CONFIGURATIONS.get(c, "(not described in this package)"),
                                 sum((p["configuration"] or "default") == c for p in runs))
                                for c in configs]
        mb["mutants"] = model["mutants"] if model else []
        # goal coverage
        cov = next((c for c in self.coverage if Path(c["rel"]).name.startswith("moving_block")), None)
        mb["coverage"] = cov
        raw = next((d for rel, d in self.inp.coverage if cov and rel == cov["rel"]), {})
        per_cfg: dict = {}
        for g, rg in zip(cov["goals"] if cov else [], raw.get("goals", [])):
            g["configuration"] = str(rg.get("configuration") or "default")
            st = per_cfg.setdefault(g["configuration"], {"labelled": 0, "reached": 0, "unreachable": 0})
            st["labelled"] += 1
            if g["status"] in ("reached", "unreachable"):
                st[g["status"]] += 1
        mb["goal_configs"] = [(c, v["labelled"], v["reached"], v["unreachable"])
                              for c, v in sorted(per_cfg.items(),
                                                 key=lambda kv: (cfg_rank.get(kv[0], 99), kv[0]))]
        files_map = raw.get("files") if isinstance(raw.get("files"), dict) else {}
        # vector files
        vfs = []
        for vf in self.vector_files:
            if not Path(vf["rel"]).name.startswith("moving_block"):
                continue
            header = dict(vf["header"])
            items = vf["items"]
            name = Path(vf["rel"]).name
            vfs.append({"vf": vf, "configuration": header.get("configuration", "default"),
                        "listed": fmt_value(files_map.get(name)) if name in files_map else "n/a",
                        "kinds": ", ".join(f"{k} {n}" for k, n in sorted(
                            _count(it["kind"] or "(none)" for it in items).items())),
                        "passed": sum(it["conformance"] == "passed" for it in items),
                        "failed": sum(it["conformance"] in ("failure", "error") for it in items),
                        "not_replayed": sum(it["conformance"] in ("not replayed", "skipped")
                                            for it in items)})
        mb["vector_files"] = vfs
        mb["vector_totals"] = {k: sum(v[k] if k != "count" else v["vf"]["count"] for v in vfs)
                               for k in ("count", "passed", "failed", "not_replayed")}
        mb["vector_totals"]["steps"] = sum(v["vf"]["steps"] for v in vfs)
        # conformance test files
        mb["conformance"] = [tf for tf in self.test_files
                             if "conformance_mb" in tf["rel"] or "moving_block" in tf["rel"]]
        # scenarios
        plots = dict(self.inp.scenario_plots)
        scen, sweeps = [], []
        for a in self.analyses:
            d = a["data"]
            schema = str(d.get("schema") or "")
            if schema.startswith("railproof/sim-summary/"):
                name = str(d.get("scenario") or a["stem"].removeprefix("scenario_"))
                gap = d.get("gap") if isinstance(d.get("gap"), dict) else None
                faults = [f for f in d.get("faults") or [] if isinstance(f, dict)]
                trains = d.get("trains") if isinstance(d.get("trains"), list) else []
                progress = d.get("progress") if isinstance(d.get("progress"), dict) else {}
                scen.append({"name": name, "analysis": a["id"], "rel": a["rel"],
                             "description": str(d.get("description") or ""),
                             "line": str(d.get("line") or ""),
                             "running_line": str(d.get("running_line") or ""),
                             "assumption": str(d.get("line_assumption") or ""),
                             "simulated_s": fmt_value(d.get("simulated_s")),
                             "trains": len(trains),
                             "train_km": fmt_value(progress.get("train_km")),
                             "faults": ", ".join(f"{t} {n}" if n > 1 else t for t, n in
                                                 _count(str(f.get("type", "?")) for f in faults).items())
                             or "none",
                             "violations": fmt_value(d.get("violations")),
                             "result": str(d.get("result") or "n/a"),
                             "gap": fmt_value(gap.get("settled_gap_m")) if gap else "n/a",
                             "plot": name if name in plots else "",
                             "log": self.inp.scenario_logs.get(name, "")})
            elif schema.startswith("railproof/sim-sweep/"):
                rows = []
                for r in d.get("runs") or []:
                    if not isinstance(r, dict):
                        continue
                    g = r.get("gap") if isinstance(r.get("gap"), dict) else {}
                    rows.append([fmt_value(r.get("leader_cap_kmh")), str(r.get("result", "n/a")),
                                 fmt_value(r.get("violations")),
                                 fmt_value(g.get("leader_speed_kmh")),
                                 fmt_value(g.get("follower_speed_kmh")),
                                 fmt_value(g.get("settled_gap_m")), fmt_value(g.get("min_m")),
                                 fmt_value(g.get("max_m")), fmt_value(g.get("window_s")),
                                 fmt_value(g.get("samples"))])
                sweeps.append({"analysis": a["id"], "rel": a["rel"],
                               "scenario": str(d.get("scenario") or ""),
                               "line": str(d.get("line") or ""), "rows": rows,
                               "grows": fmt_value(d.get("gap_grows_with_speed")),
                               "result": str(d.get("result") or "n/a")})
        mb["scenarios"] = scen
        mb["sweeps"] = sweeps
        shown = {s["plot"] for s in scen if s["plot"]}
        mb["plots"] = [{"name": n, "src": f"scenario_plots/{n}.svg",
                        "scenario": next((s for s in scen if s["plot"] == n), None)}
                       for n, _ in self.inp.scenario_plots]
        mb["plots_without_summary"] = sorted(set(plots) - shown)
        mb["present"] = bool(mb["requirements"] or model or cov or vfs or scen or plots)
        self.mb = mb

    def _capability(self, prefixes: tuple, stem: str, conformance: str) -> dict:
        """A capability chapter's common data: its requirements (by ID prefix), the model
        models/<stem>.pml with its runs and mutants, its goal coverage and vector files
        (<stem>*), and its conformance test file (results/tests/<conformance>.xml)."""
        return {"requirements": [r for r in self.requirements if r["id"].startswith(prefixes)],
                "model": next((mo for mo in self.models if mo["stem"] == stem
                               or mo["model"].endswith(f"{stem}.pml")), None),
                "coverage": next((c for c in self.coverage
                                  if Path(c["rel"]).name.startswith(stem)), None),
                "vector_files": [vf for vf in self.vector_files
                                 if Path(vf["rel"]).name.startswith(stem)],
                "conformance": [tf for tf in self.test_files if conformance in tf["rel"]]}

    # -- re-adhesion chapter --------------------------------------------------------------
    def _readhesion(self):
        """The data of the re-adhesion chapter: REQ-RA requirements, the readhesion model's
        runs, mutants, goal coverage, vectors and conformance, the odometry study on the
        Box2D wheel-rail scenarios (error bound per event, baseline comparison, margin and
        clearing-time tables) and its plots."""
        ra = self._capability(("REQ-RA-",), "readhesion", "conformance_ra")
        ra["study"] = next((a for a in self.analyses if a["stem"] == "odometry_study"), None)
        ra["plots"] = [{"name": n, "src": f"odometry_plots/{n}.svg"}
                       for n, _ in self.inp.odometry_plots]
        ra["present"] = bool(ra["requirements"] or ra["model"] or ra["study"])
        self.ra = ra

    # -- level-crossing chapter ----------------------------------------------------------
    def _level_crossing(self):
        """The data of the level-crossing chapter: REQ-LC requirements, the level_crossing
        model's runs, mutants, goal coverage, vectors and conformance, the warning-time study
        and its plots, and the peer cross-check (every identifier it names must exist)."""
        lc = self._capability(("REQ-LC-",), "level_crossing", "conformance_lc")
        lc["study"] = next((a for a in self.analyses if a["stem"] == "warning_study"), None)
        lc["plots"] = [{"name": n, "src": f"crossing_plots/{n}.svg"}
                       for n, _ in self.inp.crossing_plots]
        known = set(self.req_ids) | {a["id"] for a in self.inp.assumptions} \
            | {h["id"] for h in self.inp.hazards}
        rows = []
        for r in self.inp.peer_check:
            text = " ".join(r.values())
            ids = sorted(set(ID_TOKEN.findall(text)))
            unknown = [i for i in ids if i not in known]
            if unknown:
                self.problems.append(f"peer cross-check (spec/{PEER_CHECK_NOTE} §7) names unknown "
                                     f"identifier(s) {', '.join(unknown)}")
            rows.append({"cells": list(r.values()), "ids": ids})
        lc["peer_header"] = list(self.inp.peer_check[0].keys()) if self.inp.peer_check else []
        lc["peer_rows"] = rows
        lc["present"] = bool(lc["requirements"] or lc["model"] or lc["study"])
        self.lc = lc

    # -- braking chapter ------------------------------------------------------------------
    def _braking(self):
        """The data of the braking chapter: REQ-BR and REQ-SC requirements, the braking
        model's runs, mutants, goal coverage, vector files and conformance test file, the
        speed-check design and margin analyses with their plots, and the SMT proofs (a
        proof that does not come back with its expected verdict from both solvers fails
        the package)."""
        br = self._capability(("REQ-BR-", "REQ-SC-"), "braking", "conformance_br")
        by_stem = {a["stem"]: a for a in self.analyses}
        br["speed_check"] = by_stem.get("speed_check_design")
        br["margins"] = by_stem.get("margins")
        # proofs
        proofs = []
        for rel, d in self.inp.proofs:
            solvers = d.get("solvers") if isinstance(d.get("solvers"), dict) else {}
            rows = []
            for ob in d.get("obligations") or []:
                if not isinstance(ob, dict):
                    continue
                res = {}
                for solver in ("z3", "cvc5"):
                    r = ob.get(solver) if isinstance(ob.get(solver), dict) else {}
                    res[solver] = (str(r.get("verdict", "n/a")), fmt_value(r.get("time_s")))
                expected = str(ob.get("expected", "n/a"))
                ok = ob.get("meets_target") is not False and all(
                    v == expected for v, _ in res.values())
                if not ok:
                    self.problems.append(f"proof {rel}: obligation {ob.get('name')} did not come "
                                         f"back {expected} from both solvers")
                reqs = [str(r) for r in ob.get("requirements") or []]
                rows.append({"name": str(ob.get("name", "?")), "requirements": reqs,
                             "links": [r for r in reqs if r in self.req_ids],
                             "expected": expected, "z3": res["z3"], "cvc5": res["cvc5"],
                             "ok": ok, "text": str(ob.get("text") or ob.get("title") or ""),
                             "file": str(ob.get("smt2") or ""),
                             "source": str(ob.get("source") or ""),
                             "counterexample": {
                                 solver: ", ".join(f"{k} = {v}" for k, v in sorted(
                                     ob[solver]["model"].items()))
                                 for solver in ("z3", "cvc5")
                                 if isinstance(ob.get(solver), dict)
                                 and isinstance(ob[solver].get("model"), dict)}})
            if str(d.get("verdict", "pass")).lower() not in ("pass", "passed", "ok"):
                self.problems.append(f"proof {rel}: verdict {d.get('verdict')!r}")
            proofs.append({"rel": rel, "rows": rows, "verdict": str(d.get("verdict", "n/a")),
                           "solvers": [(k, fmt_value(v.get("version") if isinstance(v, dict) else v))
                                       for k, v in sorted(solvers.items())],
                           "command": str(d.get("command") or "")})
        br["proofs"] = proofs
        br["plots"] = [{"name": n, "src": f"braking_plots/{n}.svg"} for n, _ in self.inp.braking_plots]
        br["present"] = bool(br["requirements"] or br["model"] or proofs or br["margins"]
                             or br["speed_check"])
        self.br = br

    # -- tool versions --------------------------------------------------------------------
    def _versions(self):
        def flat(prefix, v, out):
            if isinstance(v, dict):
                for k, x in v.items():
                    flat(f"{prefix}.{k}" if prefix else str(k), x, out)
            else:
                out.append((prefix, fmt_value(v)))
        self.tool_versions = []
        if self.inp.tool_versions is not None:
            flat("", self.inp.tool_versions, self.tool_versions)
        self.spin_versions = [(m["model"], m["spin_version"]) for m in self.models]
        self.doc_versions = [("Python", ".".join(map(str, sys.version_info[:3])))]
        for dist in ("Sphinx", "sphinx-needs", "sphinx-test-reports", "docutils", "Jinja2", "PyYAML"):
            try:
                self.doc_versions.append((dist, metadata.version(dist)))
            except metadata.PackageNotFoundError:
                self.doc_versions.append((dist, "not installed"))
        gens = sorted({fmt_value(h.get("generator")) for _, h, _ in self.inp.vectors if h.get("generator")})
        self.generator_versions = [("vector generator", g) for g in gens]

    # -- overall --------------------------------------------------------------------------
    def _verdict(self):
        if self.problems:
            self.verdict = "FAIL"
        elif self.incomplete:
            self.verdict = "INCOMPLETE"
        else:
            self.verdict = "PASS"
        nprops = sum(len(m["properties"]) for m in self.models)
        nmut = sum(len(m["mutants"]) for m in self.models)
        self.counts = {
            "requirements": len(self.requirements), "requirements_ok": self.req_ok,
            "sil4": sum(1 for r in self.requirements if r["sil"] == "4"),
            "hazards": len(self.hazards), "assumptions": len(self.assumptions),
            "models": len(self.models), "properties": nprops,
            "properties_verified": sum(m["verified"] for m in self.models),
            "assertions": sum(len(m["assertions"]) for m in self.models),
            "assertions_verified": sum(m["assertions_verified"] for m in self.models),
            "mutants": nmut, "mutants_rejected": sum(m["rejected"] for m in self.models),
            "vector_files": len(self.vector_files),
            "vectors": sum(f["count"] for f in self.vector_files),
            "vector_steps": sum(f["steps"] for f in self.vector_files),
            "goals_labelled": sum(c["labelled"] for c in self.coverage),
            "goals_reached": sum(c["reached"] for c in self.coverage),
            "goals_unreachable": sum(len(c["unreachable"]) for c in self.coverage),
            "test_files": len(self.test_files),
            "test_cases": sum(f["cases"] for f in self.test_files),
            "tests_passed": self.test_totals["passed"], "tests_failed": self.test_totals["failure"],
            "tests_errors": self.test_totals["error"], "tests_skipped": self.test_totals["skipped"],
            "tests_rendered_from_xml": self.own_rendered,
            "vectors_replayed_passed": self.conformance["passed"],
            "vectors_replay_failed": self.conformance["failed"],
            "vectors_not_replayed": self.conformance["not_replayed"] + self.conformance["skipped"],
            "analyses": len(self.analyses),
            "analyses_pass": sum(a["outcome"] == "pass" for a in self.analyses),
        }


# --------------------------------------------------------------------------------------
# rendering


def _jinja_env(template_dir: Path):
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(template_dir)),
        undefined=jinja2.StrictUndefined, autoescape=False,
        trim_blocks=True, lstrip_blocks=True, keep_trailing_newline=True,
        extensions=["jinja2.ext.do"])
    env.filters["rst"] = rst_escape
    env.filters["line"] = one_line
    env.filters["num"] = fmt_value
    env.filters["rows"] = lambda items, *keys: [[it.get(k, "") for k in keys] for it in items]
    env.filters["underline"] = lambda text, ch="=": ch * max(len(str(text)), 3)
    return env


def _write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", encoding="utf-8", newline="\n") as fh:
        fh.write(text)


def render_sources(model: Model, evidence_dir: Path, src_dir: Path) -> list:
    """Copy evidence/ (without its templates) to src_dir and write the generated pages."""
    template_dir = evidence_dir / "templates"
    if not (evidence_dir / "conf.py").is_file() or not template_dir.is_dir():
        raise PipelineError(f"{evidence_dir}: evidence sources (conf.py, templates/) not found")
    shutil.copytree(evidence_dir, src_dir,
                    ignore=shutil.ignore_patterns("templates", "__pycache__", "*.pyc", "_build",
                                                  "README.md"))
    env = _jinja_env(template_dir)
    pages = ["overview", "traceability", "hazards", "model_checking", "moving_block", "braking",
             "readhesion", "level_crossing", "test_generation", "tests", "analysis", "tool_versions", "manifest"]
    for name, path in model.inp.scenario_plots:     # embedded by the moving-block chapter
        (src_dir / "scenario_plots").mkdir(parents=True, exist_ok=True)
        shutil.copyfile(path, src_dir / "scenario_plots" / f"{name}.svg")
    for sub, plots in (("braking_plots", model.inp.braking_plots),     # braking chapter
                       ("odometry_plots", model.inp.odometry_plots),   # re-adhesion chapter
                       ("crossing_plots", model.inp.crossing_plots)):  # level-crossing chapter
        for name, path in plots:
            (src_dir / sub).mkdir(parents=True, exist_ok=True)
            shutil.copyfile(path, src_dir / sub / f"{name}.svg")
    ctx = {"m": model, "inp": model.inp}
    for page in pages:
        _write(src_dir / f"{page}.rst", env.get_template(f"{page}.rst.jinja").render(**ctx))
    for vf in model.vector_files:
        _write(src_dir / f"{vf['page']}.rst",
               env.get_template("vectors.rst.jinja").render(vf=vf, **ctx))
    req_tpl = env.get_template("requirement.rst.jinja")
    for r in model.requirements:
        _write(src_dir / f"{r['page']}.rst", req_tpl.render(r=r, **ctx))
    _write(src_dir / "replay_commands.inc", env.get_template("replay_commands.inc.jinja").render(**ctx))
    return pages + [vf["page"] for vf in model.vector_files] + [r["page"] for r in model.requirements]


def copy_inputs(inp: Inputs, inputs_dir: Path) -> list:
    """Verbatim copies of every input under OUT/inputs; returns [(rel, sha256, bytes)]."""
    rows = []
    for f in sorted(inp.files, key=lambda x: x.rel):
        dest = inputs_dir / f.rel
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(f.source, dest)
        rows.append({"path": f"inputs/{f.rel}", "sha256": sha256_file(dest),
                     "bytes": dest.stat().st_size})
    return rows


def check_toolchain() -> None:
    """Fail early, in one line, when the documentation tool chain cannot work."""
    import inspect

    try:
        import sphinx  # noqa: F401
        import sphinx_needs.api
        import sphinxcontrib.test_reports  # noqa: F401
    except ImportError as exc:
        raise PipelineError(f"the Sphinx tool chain is not installed ({exc.name}); install "
                            "testgen/requirements.txt into the Python environment") from None
    if "schema" not in inspect.signature(sphinx_needs.api.add_extra_option).parameters:
        raise PipelineError(
            f"sphinx-needs {metadata.version('sphinx-needs')} cannot run sphinx-test-reports "
            f"{metadata.version('sphinx-test-reports')}: its add_extra_option() has no 'schema' "
            "argument (added in sphinx-needs 6.0.1); pin sphinx-needs>=6.0.1")


def run_sphinx(src_dir: Path, html_dir: Path, doctree_dir: Path, out_dir: Path) -> int:
    """sphinx-build -b html with everything that could vary between machines fixed.
    Returns the number of warnings; raises PipelineError on any error."""
    env = dict(os.environ)
    env.update({"SOURCE_DATE_EPOCH": SOURCE_DATE_EPOCH, "PYTHONHASHSEED": "0",
                "PYTHONDONTWRITEBYTECODE": "1", "TZ": "UTC", "LC_ALL": "C.UTF-8", "LANG": "C.UTF-8"})
    warn_file = out_dir / "sphinx-warnings.log"
    log_file = out_dir / "sphinx-output.log"
    cmd = [sys.executable, "-m", "sphinx", "-b", "html", "-E", "-j", "1", "-d", str(doctree_dir),
           "-w", str(warn_file), "--keep-going", str(src_dir), str(html_dir)]
    with log_file.open("w", encoding="utf-8") as log:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env,
                                text=True, encoding="utf-8", errors="replace")
        assert proc.stdout is not None
        tail: list = []
        for line in proc.stdout:
            log.write(line)
            if line.strip():
                tail = (tail + [line.strip()])[-40:]
            line = line.rstrip()
            if line.startswith(("reading sources", "writing output", "build succeeded",
                                "build finished", "copying", "generating indices", "dumping")) \
                    or "ERROR" in line or "WARNING" in line:
                _log(f"sphinx: {line[:200]}")
        rc = proc.wait()
    warnings = warn_file.read_text(encoding="utf-8", errors="replace") if warn_file.exists() else ""
    errors = [ln for ln in warnings.splitlines()
              if re.search(r"(?:^|:\s)(?:ERROR|CRITICAL|SEVERE)\b", ln)]
    if rc != 0 or errors:
        crash = [ln for ln in tail if re.search(r"error|exception", ln, re.IGNORECASE)]
        first = errors[0] if errors else (crash or tail or ["no output"])[-1]
        raise PipelineError(f"sphinx-build failed (exit {rc}, {len(errors)} error(s)): {first.strip()} "
                            f"[log: {log_file}]")
    return sum(1 for ln in warnings.splitlines() if "WARNING" in ln)


def _walk(base: Path, top: Path, skip) -> list:
    rows = []
    for p in sorted(top.rglob("*")):
        if not p.is_file():
            continue
        rel = p.relative_to(base).as_posix()
        if skip(rel):
            continue
        rows.append({"path": rel, "sha256": sha256_file(p), "bytes": p.stat().st_size})
    return rows


def write_manifest(out_dir: Path, input_rows: list) -> dict:
    def skip(rel: str) -> bool:
        parts = rel.split("/")
        return ("__pycache__" in parts or parts[-1].startswith(".buildinfo") or ".doctrees" in parts
                or rel == "html/schema_violations.json")

    artifacts = list(input_rows)
    artifacts += _walk(out_dir, out_dir / "src", skip)
    artifacts += _walk(out_dir, out_dir / "html", skip)
    artifacts.append({"path": "evidence.json", "sha256": sha256_file(out_dir / "evidence.json"),
                      "bytes": (out_dir / "evidence.json").stat().st_size})
    artifacts.sort(key=lambda a: a["path"])
    manifest = {"schema": MANIFEST_SCHEMA, "algorithm": "sha256", "artifacts": artifacts,
                "excluded": [{"path": k, "reason": v} for k, v in EXCLUDED.items()]}
    text = json.dumps(manifest, indent=2, sort_keys=True) + "\n"
    _write(out_dir / "manifest.json", text)
    lines = [f"{a['sha256']}  {a['path']}" for a in artifacts]
    lines.append(f"{hashlib.sha256(text.encode()).hexdigest()}  manifest.json")
    _write(out_dir / "manifest.sha256", "\n".join(lines) + "\n")
    return manifest


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


def build(spec_dir, results_dir, repo_root, out_dir, tool_versions=None) -> dict:
    spec_dir, results_dir = Path(spec_dir), Path(results_dir)
    repo_root, out_dir = Path(repo_root), Path(out_dir)
    evidence_dir = repo_root / "evidence"
    _check_out_dir(out_dir, repo_root, spec_dir, results_dir)

    _log(f"reading specification {spec_dir} and results {results_dir}")
    inp = load_inputs(spec_dir, results_dir, repo_root, tool_versions)
    check_toolchain()
    args = [("--spec", _display_path(spec_dir, repo_root, "SPEC_DIR")),
            ("--results", _display_path(results_dir, repo_root, "RESULTS_DIR")),
            ("--src", "."), ("--out", "OUT_DIR")]
    if tool_versions:
        args.append(("--tool-versions",
                     _display_path(Path(tool_versions), repo_root, "TOOL_VERSIONS_JSON")))
    command = " \\\n    ".join(["PYTHONPATH=testgen python -m railproof_testgen evidence"]
                                  + [f"{k} {shlex.quote(v)}" for k, v in args])
    model = Model(inp, command)
    c = model.counts
    _log(f"rendering {c['requirements']} requirements, {c['hazards']} hazards, "
         f"{c['assumptions']} assumptions, {c['properties']} properties, {c['mutants']} mutants, "
         f"{c['vectors']} vectors, {c['test_cases']} test cases, {c['analyses']} analyses")
    for note in inp.missing:
        _log(f"not available in this run: {note}")

    out_dir.mkdir(parents=True, exist_ok=True)
    for sub in ("inputs", "src", "html", ".doctrees"):
        if (out_dir / sub).exists():
            shutil.rmtree(out_dir / sub)
    for f in ("manifest.json", "manifest.sha256", "evidence.json", "sphinx-warnings.log",
              "sphinx-output.log"):
        (out_dir / f).unlink(missing_ok=True)

    input_rows = copy_inputs(inp, out_dir / "inputs")
    model.input_rows = input_rows
    model.excluded = [[k, v] for k, v in EXCLUDED.items()]
    pages = render_sources(model, evidence_dir, out_dir / "src")
    _log(f"wrote {len(pages)} generated pages; running sphinx-build (html)")
    nwarn = run_sphinx(out_dir / "src", out_dir / "html", out_dir / ".doctrees", out_dir)
    shutil.rmtree(out_dir / ".doctrees", ignore_errors=True)   # not part of the package
    if nwarn:
        _log(f"sphinx-build reported {nwarn} warning(s): see {out_dir / 'sphinx-warnings.log'}")

    summary = {"schema": "railproof/evidence/1", "verdict": model.verdict,
               "problems": model.problems, "not_available": inp.missing, "counts": c}
    _write(out_dir / "evidence.json", json.dumps(summary, indent=2, sort_keys=True) + "\n")
    _log("hashing the package")
    manifest = write_manifest(out_dir, input_rows)
    _log(f"wrote {out_dir / 'manifest.json'} ({len(manifest['artifacts'])} artifacts); "
         f"verdict {model.verdict}")
    return {"manifest": manifest, "summary": summary, "warnings": nwarn}


def _run(a) -> int:
    build(a.spec, a.results, a.src, a.out, a.tool_versions)
    return 0


def register(sub):
    p = sub.add_parser(
        "evidence",
        help="render the assessor's evidence package (Sphinx + sphinx-needs) and its manifest",
        description="Render spec/ and the pipeline's results into an HTML evidence package with "
                    "Sphinx, sphinx-needs and sphinx-test-reports, and write a SHA-256 manifest.")
    p.add_argument("--spec", required=True, help="spec/ directory")
    p.add_argument("--results", required=True,
                   help="results directory (spin/, vectors/, tests/, analysis/, trace.json)")
    p.add_argument("--src", required=True, help="repository root (its evidence/ holds the sources)")
    p.add_argument("--out", required=True, help="output directory (inputs/, src/, html/, manifest)")
    p.add_argument("--tool-versions", default=None, help="JSON object of tool names to versions")
    p.set_defaults(func=_run)
