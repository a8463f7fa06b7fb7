"""Loading the evidence's inputs: spec/ and the build's results directory.

Every file read is recorded (``Inputs.files``) and copied verbatim into the package. A
malformed file stops the build with ``file: entry: reason``; a result file the registry
expects but the build did not write is not an error here: it is noted in
``Inputs.missing`` and fails the verdict (see context.py).

results/ (formats: spec/design/tg.md §8 and the writers named below)::

    registry.json                 the capability registry (railproof_testgen registry --json)
    trace.json                    requirement links (railproof_testgen trace)
    layout.json                   module boundaries (railproof_testgen layout)
    tool-versions.json            tool chain (railproof_testgen toolversions)
    spin/<model>.json             model checking (railproof_testgen verify)
    vectors/<model>[.<cfg>].jsonl, <model>.coverage.json   vectors and goal coverage
    proofs/<cap>.json, proofs/<cap>/**                      SMT proofs
    analysis/*.json               studies of the offline tools
    <cap>/**                      plots and details of a capability's studies
    tests/                        the ctest run and its detail files (junit.py)
"""
from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path

from .. import spec as spec_mod
from .. import spin as spin_mod
from ..errors import PipelineError, SpecError
from . import identity, junit

TRACE_SCHEMA = "railproof/trace/1"
REGISTRY_SCHEMA = "railproof/registry/1"
LAYOUT_SCHEMA = "railproof/layout/1"
SVG_HEAD = (b"<?xml", b"<svg")


@dataclass
class InputFile:
    source: Path      # where it was read
    rel: str          # path under OUT/inputs (posix)


@dataclass
class Inputs:
    spec_dir: Path
    results_dir: Path
    repo_root: Path
    registry: list = field(default_factory=list)       # capability entries of registry.json
    fault_owners: list = field(default_factory=list)   # the capabilities and the units, each with its faults
    requirements: list = field(default_factory=list)
    hazards: list = field(default_factory=list)
    assumptions: list = field(default_factory=list)
    parameters: dict = field(default_factory=dict)
    justifications: dict = field(default_factory=dict)  # UR id -> entry (spec/justifications)
    trace: dict = field(default_factory=dict)
    spin: list = field(default_factory=list)          # [(rel, data)]
    vectors: list = field(default_factory=list)       # [(rel, header, [vector])]
    coverage: list = field(default_factory=list)      # [(rel, data)]
    tests: junit.TestRun = field(default_factory=junit.TestRun)
    analysis: list = field(default_factory=list)      # [(rel, data)]
    proofs: list = field(default_factory=list)        # [(rel, data)] of proofs/*.json
    result_dirs: dict = field(default_factory=dict)   # dir -> [(file name, Path)] (results/<dir>/*)
    layout: dict | None = None
    tool_versions: dict | None = None
    identity: dict | None = None                      # the configuration rendered from (identity.py)
    model_copies: dict = field(default_factory=dict)  # model path -> its copy under inputs/
    _rels: set = field(default_factory=set)
    extra: dict = field(default_factory=dict)         # what chapter modules load (by capability)
    files: list = field(default_factory=list)         # [InputFile]
    missing: list = field(default_factory=list)       # result files the build did not write

    def add(self, path: Path, rel: str | None = None) -> str:
        """Record a file as an input of the package (once); returns its path under results/."""
        rel = rel or f"results/{path.relative_to(self.results_dir).as_posix()}"
        if rel not in self._rels:
            self._rels.add(rel)
            self.files.append(InputFile(path, rel))
        return rel.removeprefix("results/")

    def plots(self, directory: str) -> list:
        """[(name, Path)] of the SVG plots of results/<directory>/."""
        return [(n[:-len(".svg")], p) for n, p in self.result_dirs.get(directory, []) if n.endswith(".svg")]


def read_json(path: Path, what: str):
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


def require(cond: bool, path: Path, entry: str, reason: str) -> None:
    if not cond:
        raise PipelineError(f"{path}: {entry}: {reason}")


def _json_object(path: Path, what: str, schema: str | None = None) -> dict:
    data = read_json(path, what)
    require(isinstance(data, dict), path, "-", "top level must be an object")
    if schema:
        require(data.get("schema") == schema, path, "schema", f"expected {schema!r}, got {data.get('schema')!r}")
    return data


def _required(inp: Inputs, rel: str, what: str, schema: str, writer: str) -> tuple:
    """(path, object) of results/<rel>, which the evidence cannot do without."""
    path = inp.results_dir / rel
    if not path.is_file():
        raise PipelineError(f"{path}: {rel} not found ({writer})")
    data = _json_object(path, what, schema)
    inp.add(path)
    return path, data


def _optional(inp: Inputs, rel: str, what: str, schema: str | None = None):
    """results/<rel> as an object, or None (noted as missing) if the build did not write it."""
    path = inp.results_dir / rel
    if not path.is_file():
        inp.missing.append(f"results/{rel}: {what} not written by the build")
        return None
    data = _json_object(path, what, schema)
    inp.add(path)
    return data


# -- spec -------------------------------------------------------------------------------


def _spec_entries(inp: Inputs, kind: str, key: str, target, seen) -> None:
    """The entries of every spec/<kind>/*.yaml file under ``key``, each with an 'id' unique
    among seen (a dict or set); appended to target (list) or stored in it (dict)."""
    for f in spec_mod.spec_files(inp.spec_dir, kind):
        data = spec_mod.load_yaml(f)
        entries = data.get(key) or []
        if not isinstance(entries, list):
            raise SpecError(f, key, "must be a list")
        for i, e in enumerate(entries):
            if not isinstance(e, dict) or "id" not in e:
                raise SpecError(f, f"{key}[{i}]", "entry needs an 'id'")
            if e["id"] in seen:
                raise SpecError(f, e["id"], "duplicate id")
            entry = dict(e, _file=f.name, _area=data.get("area", ""))
            if isinstance(target, dict):
                target[str(e["id"])] = entry
            else:
                target.append(entry)
                seen.add(e["id"])
        inp.add(f, f"spec/{f.relative_to(inp.spec_dir).as_posix()}")


def load_spec(inp: Inputs) -> None:
    spec_dir = inp.spec_dir
    if not spec_dir.is_dir():
        raise PipelineError(f"{spec_dir}: specification directory not found")
    if not spec_mod.spec_files(spec_dir, "requirements"):
        raise PipelineError(f"{spec_dir / 'requirements'}: no requirement files (*.yaml) found")
    seen: set = set()
    for kind, target in (("requirements", inp.requirements), ("hazards", inp.hazards),
                         ("assumptions", inp.assumptions)):
        _spec_entries(inp, kind, kind, target, seen)
    _spec_entries(inp, "justifications", "justifications", inp.justifications, inp.justifications)
    inp.parameters = spec_mod.load_parameters(spec_dir)
    for area in sorted(inp.parameters):
        f = Path(inp.parameters[area]["file"])
        inp.add(f, f"spec/{f.relative_to(spec_dir).as_posix()}")


# Design notes of no single capability that a page links to (the system page).
SYSTEM_DESIGN_NOTES = ("design/units.md", "design/sim.md")


def load_design_notes(inp: Inputs) -> None:
    """The design note of every registered capability (spec/design/<cap>.md), linked from
    its chapter, and those of the units and the simulator, linked from the system page."""
    rels = [cap["design"].removeprefix("spec/") for cap in inp.registry] + list(SYSTEM_DESIGN_NOTES)
    for rel in rels:
        if (inp.spec_dir / rel).is_file():
            inp.add(inp.spec_dir / rel, f"spec/{rel}")


# -- results ----------------------------------------------------------------------------


def load_registry(inp: Inputs) -> None:
    path, data = _required(inp, "registry.json", "registry", REGISTRY_SCHEMA,
                           "the build writes it from spec/capabilities.yaml; the chapters are driven by it")
    caps = data.get("capabilities")
    require(isinstance(caps, list) and caps, path, "capabilities", "must be a non-empty list")
    for i, c in enumerate(caps):
        require(isinstance(c, dict) and isinstance(c.get("name"), str), path, f"capabilities[{i}]",
                "needs a 'name'")
        for key in ("areas", "models", "faults", "studies", "runtime_parts"):
            require(isinstance(c.get(key), list), path, c["name"], f"'{key}' must be a list")
        for key in ("title", "design", "chapter"):
            require(isinstance(c.get(key), str), path, c["name"], f"'{key}' must be a string")
    inp.registry = caps
    units = data.get("units") or {}
    require(isinstance(units, dict) and isinstance(units.get("faults", []), list), path, "units",
            "must be an object with a list of 'faults'")
    inp.fault_owners = caps + [{"name": "units", "title": units.get("title", ""), "faults": units.get("faults", [])}]


def load_trace(inp: Inputs) -> None:
    path, data = _required(inp, "trace.json", "trace.json", TRACE_SCHEMA,
                           "the traceability step writes it; run it before rendering the evidence")
    reqs = data.get("requirements")
    require(isinstance(reqs, list), path, "requirements", "must be a list")
    for i, r in enumerate(reqs):
        require(isinstance(r, dict) and "id" in r, path, f"requirements[{i}]", "needs an 'id'")
        require(isinstance(r.get("links", {}), dict), path, r["id"], "'links' must be an object")
    inp.trace = data


def _entries(path: Path, data: dict, key: str, needs: tuple) -> None:
    require(isinstance(data.get(key, []), list), path, key, "must be a list")
    for i, e in enumerate(data.get(key, [])):
        require(isinstance(e, dict) and all(k in e for k in needs), path, f"{key}[{i}]",
                f"needs {' and '.join(repr(k) for k in needs)}")


def load_spin(inp: Inputs) -> None:
    for f in sorted((inp.results_dir / "spin").glob("*.json")):
        data = _json_object(f, "SPIN result")
        for key in ("properties", "assertions", "mutants"):
            _entries(f, data, key, ("name", "verdict"))
        inp.spin.append((inp.add(f), data))
        _copy_model_source(inp, data.get("model"))


def _copy_model_source(inp: Inputs, model) -> None:
    """A verbatim copy of the checked model (inputs/source/models/...) when the result names
    a file inside the source tree, with the shared parts it includes (models/include/...), so
    that the package holds everything a replay of the model needs."""
    if not isinstance(model, str) or not model or model in inp.model_copies:
        return
    root = inp.repo_root.resolve()
    path = (inp.repo_root / model).resolve()
    if root in path.parents and path.is_file():
        inp.model_copies[model] = inp.add(path, f"source/{path.relative_to(root).as_posix()}")
        for inc in spin_mod.shared_includes(path):
            rel = inc.resolve().relative_to(root).as_posix()
            if rel not in inp.model_copies:
                inp.model_copies[rel] = inp.add(inc.resolve(), f"source/{rel}")


def load_vectors(inp: Inputs) -> None:
    vdir = inp.results_dir / "vectors"
    seen: dict = {}
    for f in sorted(vdir.glob("*.jsonl")):
        header, vectors = None, []

        def malformed(lineno, exc, f=f):
            raise PipelineError(f"{f}: line {lineno}: malformed JSON: {exc.msg}") from None

        with f.open(encoding="utf-8") as fh:
            for lineno, obj in spec_mod.jsonl_records(fh, malformed):
                require(isinstance(obj, dict), f, f"line {lineno}", "must be an object")
                if obj.get("kind") == "header":
                    require(header is None and not vectors, f, f"line {lineno}",
                            "the header must be the first line and appear once")
                    header = obj
                    continue
                require(header is not None, f, f"line {lineno}", "vector before the header line")
                require(isinstance(obj.get("id"), str) and obj["id"], f, f"line {lineno}",
                        "vector needs an 'id'")
                require(obj["id"] not in seen, f, obj["id"],
                        f"duplicate vector id (also in {seen.get(obj['id'])})")
                seen[obj["id"]] = f.name
                vectors.append(obj)
        require(header is not None, f, "line 1", "missing header line")
        inp.vectors.append((inp.add(f), header, vectors))
    for f in sorted(vdir.glob("*.coverage.json")):
        data = _json_object(f, "goal coverage")
        require(isinstance(data.get("goals"), list), f, "goals", "must be a list")
        _entries(f, data, "goals", ("id", "status"))
        inp.coverage.append((inp.add(f), data))


def load_tests(inp: Inputs) -> None:
    inp.tests = junit.load_run(inp.results_dir, inp.missing)
    if inp.tests.ctest is not None:
        inp.add(inp.results_dir / junit.CTEST_JUNIT)
    for rel in sorted(inp.tests.details):
        inp.add(inp.results_dir / rel)


def load_analysis(inp: Inputs) -> None:
    for f in sorted((inp.results_dir / "analysis").glob("*.json")):
        inp.analysis.append((inp.add(f), _json_object(f, "analysis result")))


def load_proofs(inp: Inputs) -> None:
    """SMT proof results (proofs/<cap>.json, written by ``railproof_testgen proofs``) and
    every file of their proofs/<cap>/ folders (obligations as replayed, solver logs)."""
    d = inp.results_dir / "proofs"
    for f in sorted(d.glob("*.json")):
        data = _json_object(f, "proof result")
        require(isinstance(data.get("obligations"), list), f, "obligations",
                "a proof result must hold a list 'obligations'")
        inp.proofs.append((inp.add(f), data))
    for f in sorted(p for p in d.glob("*/**/*") if p.is_file()):
        inp.add(f)


def load_result_dir(inp: Inputs, directory: str) -> None:
    """Every file of results/<directory>/ (plots and per-item details of a capability's
    studies) as an input; the SVG plots are checked to be SVG."""
    d = inp.results_dir / directory
    files = []
    for f in sorted(p for p in d.rglob("*") if p.is_file()):
        if f.suffix == ".svg":
            require(f.read_bytes()[:4096].lstrip().startswith(SVG_HEAD), f, "-", "not an SVG image")
        inp.add(f)
        files.append((f.relative_to(d).as_posix(), f))
    inp.result_dirs[directory] = files


def load_layout(inp: Inputs) -> None:
    path = inp.results_dir / "layout.json"
    data = _optional(inp, "layout.json", "the module-boundary check (layout)", LAYOUT_SCHEMA)
    if data is not None:
        require(isinstance(data.get("violations"), list), path, "violations", "must be a list")
        require(isinstance(data.get("targets"), dict), path, "targets", "must be an object")
        for name, t in data["targets"].items():
            require(isinstance(t, dict) and isinstance(t.get("kind"), str)
                    and isinstance(t.get("links"), list) and isinstance(t.get("closure"), list),
                    path, name, "a target needs 'kind', 'links' and 'closure'")
    inp.layout = data


def load_tool_versions(inp: Inputs) -> None:
    inp.tool_versions = _optional(inp, "tool-versions.json", "the tool versions")


def load_markdown_table(inp: Inputs, rel: str, heading: str) -> list:
    """The first Markdown table of the section ``heading`` (a regular expression matching
    the heading line) of spec/<rel>, as a list of {column: cell}; [] if the file or the
    section has none. The file becomes an input."""
    note = inp.spec_dir / rel
    if not note.is_file():
        return []
    inp.add(note, f"spec/{rel}")
    text = note.read_text(encoding="utf-8")
    start = re.search(heading, text, re.M)
    if not start:
        return []
    section = text[start.end():]
    end = re.search(r"^## ", section, re.M)
    section = section[:end.start()] if end else section
    rows = [ln.strip() for ln in section.splitlines() if ln.strip().startswith("|")]
    if len(rows) < 3:
        return []
    cells = [[c.strip() for c in r.strip("|").split("|")] for r in rows]
    header, body = cells[0], [c for c in cells[2:] if any(c)]
    for i, c in enumerate(body):
        require(len(c) == len(header), note, f"table row {i + 1}",
                f"{len(c)} cells where the header has {len(header)}")
    return [dict(zip(header, c)) for c in body]


def load_inputs(spec_dir: Path, results_dir: Path, repo_root: Path) -> Inputs:
    from . import chapters

    inp = Inputs(Path(spec_dir), Path(results_dir), Path(repo_root))
    load_spec(inp)
    if not inp.results_dir.is_dir():
        raise PipelineError(f"{inp.results_dir}: results directory not found")
    load_registry(inp)
    load_design_notes(inp)
    load_trace(inp)
    load_spin(inp)
    load_vectors(inp)
    load_tests(inp)
    load_analysis(inp)
    load_proofs(inp)
    for directory in chapters.result_dirs(inp.registry):
        load_result_dir(inp, directory)
    load_layout(inp)
    load_tool_versions(inp)
    # the build directory is the one that holds the results
    inp.identity = identity.collect(inp.repo_root, inp.results_dir.parent)
    chapters.load(inp)
    return inp
