"""The capability registry (spec/capabilities.yaml): one entry per capability, by the one
short name every tree uses. This module loads it (schema: spec/schemas/capabilities.schema.json),
checks that the registry and the tree agree, and writes what the build reads from it.

``railproof_testgen registry --spec spec --repo . [--check] [--cmake F] [--faults-header F]``

The check (every finding printed as ``file: entry: reason``; any error exits 1):
- a capability's name is the lower-case form of its first requirement area; names and areas
  are unique; every area has spec/requirements/<area>.yaml declaring that area;
- its design note spec/design/<name>.md, its evidence chapter evidence/templates/<name>.rst.jinja,
  and for a capability with models its vector schema spec/schemas/vectors_<name>.schema.json
  and its vector part testgen/railproof_testgen/capabilities/<name>.py exist;
- each model models/<model>.pml exists and its configurations (from the @property, @goal and
  @mutant annotations and the @variant lines) are exactly the ones the registry lists;
- the runtime module cpp/runtime/<name>/ has a CMakeLists.txt and one source folder per side
  part (src/onboard, src/wayside; src/ or src/common for the common part), a conformance
  runner cpp/runtime/<name>/conformance/ if the registry says so;
- every registered seeded fault appears as RAILPROOF_FAULT(<id>) in the capability's runtime
  sources, and every RAILPROOF_FAULT(...) in cpp/runtime is registered under its capability;
- proofs/<name>/ exists exactly when the registry says the capability has proofs;
- nothing is orphaned: every spec/requirements, spec/parameters and spec/justifications file,
  every model and shared model part (models/include/<cap>_*.pml), every vector schema, every
  proofs/ folder and every cpp/runtime or cpp/offline folder belongs to a registered
  capability (or to the shared modules listed in SHARED).
"""
from __future__ import annotations

import json
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

import jsonschema

from . import SPEC_DIR, add_command
from . import spin as spin_mod
from .errors import SpecError
from .files import write_atomic
from .spec import load_yaml

REGISTRY = "capabilities.yaml"
SCHEMA = "schemas/capabilities.schema.json"
# Runtime and offline folders that belong to no single capability.
SHARED = {"runtime": {"core", "messages", "units"}, "offline": {"common", "sim"}}
SIDES = ("common", "onboard", "wayside")
_FAULT_USE = re.compile(r"\bRAILPROOF_FAULT\((\w+)\)")


def _named(template: str):
    """A read-only property: the path template with the object's name filled in."""
    return property(lambda self: template.format(name=self.name))


@dataclass
class Fault:
    id: str
    text: str
    killed_by: list


@dataclass
class Model:
    name: str
    configurations: list

    path = _named("models/{name}.pml")


@dataclass
class Capability:
    name: str
    title: str
    sources: list
    areas: list
    models: list = field(default_factory=list)
    parts: list = field(default_factory=list)
    conformance: bool = False
    proofs: bool = False
    faults: list = field(default_factory=list)
    studies: list = field(default_factory=list)

    design = _named("spec/design/{name}.md")
    chapter = _named("evidence/templates/{name}.rst.jinja")
    vector_schema = _named("spec/schemas/vectors_{name}.schema.json")
    vector_part = _named("testgen/railproof_testgen/capabilities/{name}.py")

    def fault(self, fid: str) -> Fault | None:
        return next((f for f in self.faults if f.id == fid), None)


@dataclass
class Registry:
    file: Path
    capabilities: list
    # The units' glue (cpp/runtime/units): a pseudo-capability "units" that only has faults.
    units: Capability | None = None

    @property
    def fault_owners(self) -> list:
        """Everything that owns seeded faults: the capabilities, then the units."""
        return self.capabilities + ([self.units] if self.units else [])

    def by_name(self, name: str) -> Capability:
        for c in self.capabilities:
            if c.name == name:
                return c
        raise KeyError(name)

    def of_area(self, area: str) -> Capability | None:
        return next((c for c in self.capabilities if area in c.areas), None)

    def of_model(self, model: str) -> Capability | None:
        stem = Path(model).stem
        return next((c for c in self.capabilities if any(m.name == stem for m in c.models)), None)

    @property
    def areas(self) -> list:
        return [a for c in self.capabilities for a in c.areas]

    @property
    def models(self) -> list:
        return [m for c in self.capabilities for m in c.models]


def load(spec_dir: Path) -> Registry:
    spec_dir = Path(spec_dir)
    path = spec_dir / REGISTRY
    data = load_yaml(path)
    try:
        schema = json.loads((spec_dir / SCHEMA).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SpecError(spec_dir / SCHEMA, "-", "file not found") from None
    errors = sorted(jsonschema.Draft202012Validator(schema).iter_errors(data), key=lambda e: list(e.path))
    if errors:
        e = errors[0]
        where = "/".join(str(p) for p in e.path) or "-"
        raise SpecError(path, where, e.message)
    caps = []
    for c in data["capabilities"]:
        rt = c.get("runtime") or {}
        caps.append(Capability(
            name=c["name"], title=c["title"], sources=list(c["sources"]), areas=list(c["areas"]),
            models=[Model(m["name"], list(m["configurations"])) for m in c.get("models") or []],
            parts=list(rt.get("parts") or []), conformance=bool(rt.get("conformance")),
            proofs=bool(c.get("proofs")),
            faults=[Fault(f["id"], f["text"], list(f["killed_by"])) for f in c.get("faults") or []],
            studies=list(c.get("studies") or [])))
    units = None
    if data.get("units"):
        u = data["units"]
        units = Capability(name="units", title=u["title"], sources=[], areas=["UNIT"],
                           faults=[Fault(f["id"], f["text"], list(f["killed_by"])) for f in u["faults"]])
    return Registry(path, caps, units)


def model_configurations(model_path: Path) -> list:
    """Every configuration a model is checked or searched in: "default" for the model's own
    configuration, then the -D symbols of the @property/@goal/@mutant [config ...] tags and of
    the @variant lines, in the order of first appearance."""
    ann = spin_mod.parse_annotations(model_path)
    seen = []

    def add(c):
        c = c or "default"
        if c not in seen:
            seen.append(c)
    for p in ann.properties:
        for c in p.configs:
            add(c)
    for v in ann.variants:
        add(v.define)
    for define, _ in ann.walk_only:
        add(define)
    for g in ann.goals:
        add(g.config)
    for m in ann.mutants:
        add(m.config)
    return seen


class Checker:
    def __init__(self, reg: Registry, repo: Path):
        self.reg, self.repo = reg, Path(repo)
        self.errors: list = []

    def err(self, file, entry, reason):
        self.errors.append(f"{file}: {entry}: {reason}")

    def rel(self, p: Path) -> str:
        try:
            return str(Path(p).relative_to(self.repo))
        except ValueError:
            return str(p)

    def need(self, rel: str, entry: str, what: str):
        if not (self.repo / rel).exists():
            self.err(rel, entry, f"missing: {what}")

    def run(self) -> list:
        reg, f = self.reg, self.rel(self.reg.file)
        names, areas = set(), set()
        for c in reg.capabilities:
            if c.name in names:
                self.err(f, c.name, "duplicate capability name")
            names.add(c.name)
            if c.name != c.areas[0].lower():
                self.err(f, c.name, f"the name must be the lower-case first area ({c.areas[0].lower()})")
            for a in c.areas:
                if a in areas:
                    self.err(f, c.name, f"area {a} belongs to two capabilities")
                areas.add(a)
                req = f"spec/requirements/{a.lower()}.yaml"
                self.need(req, c.name, f"requirements of area {a}")
                if (self.repo / req).exists():
                    declared = load_yaml(self.repo / req).get("area")
                    if declared != a:
                        self.err(req, "area", f"declares {declared!r}, the registry gives the file area {a}")
            self.need(c.design, c.name, "design note")
            self.need(c.chapter, c.name, "evidence chapter")
            if c.models:
                self.need(c.vector_schema, c.name, "vector schema")
                self.need(c.vector_part, c.name, "the capability's part of vector generation")
            for m in c.models:
                if not m.name.startswith(c.name):
                    self.err(f, f"{c.name}/{m.name}", f"a model of {c.name} is named {c.name} or {c.name}_<part>")
                mp = self.repo / m.path
                if not mp.exists():
                    self.err(m.path, c.name, "missing: model")
                    continue
                try:
                    have = model_configurations(mp)
                except SpecError as exc:
                    self.err(exc.file, exc.entry, exc.reason)
                    continue
                if sorted(have) != sorted(m.configurations):
                    self.err(f, f"{c.name}/{m.name}", f"configurations {m.configurations} differ from the "
                                                      f"model's {have}")
            self._runtime(c, f)
            proofs = self.repo / "proofs" / c.name
            if c.proofs and not proofs.is_dir():
                self.err(f"proofs/{c.name}", c.name, "missing: the registry says the capability has proofs")
            if not c.proofs and proofs.exists():
                self.err(f"proofs/{c.name}", c.name, "proofs exist but the registry does not list them")
        self._faults(f)
        self._orphans(names, areas)
        return self.errors

    def _runtime(self, c: Capability, f: str):
        base = f"cpp/runtime/{c.name}"
        if not c.parts:
            if (self.repo / base).exists():
                self.err(base, c.name, "runtime module exists but the registry lists no runtime parts")
            return
        self.need(f"{base}/CMakeLists.txt", c.name, "runtime module CMakeLists.txt")
        for p in c.parts:
            d = self.repo / base / "src" / p
            if not d.is_dir() and (p == "common" or len(c.parts) == 1):
                d = self.repo / base / "src"  # a one-part module keeps its sources in src/
            if not d.is_dir() or not any(d.glob("*.cpp")):
                self.err(self.rel(d), c.name, f"no sources of the {p} part")
        for side in ("onboard", "wayside"):
            if (self.repo / base / "src" / side).is_dir() and side not in c.parts:
                self.err(f"{base}/src/{side}", c.name, f"the registry lists no {side} part")
        if c.conformance:
            self.need(f"{base}/conformance", c.name, "conformance runner")

    def _faults(self, f: str):
        used = {}
        for src in sorted((self.repo / "cpp" / "runtime").glob("*/src/**/*.cpp")):
            cap = src.relative_to(self.repo / "cpp" / "runtime").parts[0]
            for m in _FAULT_USE.finditer(src.read_text(encoding="utf-8")):
                used.setdefault(m.group(1), set()).add(cap)
        for c in self.reg.fault_owners:
            seen = set()
            for flt in c.faults:
                if flt.id in seen:
                    self.err(f, flt.id, "duplicate seeded fault")
                seen.add(flt.id)
                if not any(flt.id.startswith(f"FAULT_{a}_") for a in c.areas):
                    self.err(f, flt.id, f"a fault of {c.name} is named FAULT_<area>_... ({', '.join(c.areas)})")
                if c.name not in used.get(flt.id, set()):
                    self.err(f, flt.id, f"no RAILPROOF_FAULT({flt.id}) in cpp/runtime/{c.name}/src")
                if "vectors" in flt.killed_by and not (c.models and c.conformance):
                    self.err(f, flt.id, "killed_by vectors needs a model and a conformance runner")
        for fid, caps in sorted(used.items()):
            for cap in sorted(caps):
                owner = next((o for o in self.reg.fault_owners if o.name == cap), None)
                if owner is None:
                    continue
                if owner.fault(fid) is None:
                    self.err(f"cpp/runtime/{cap}/src", fid, f"seeded fault not registered under {cap}")

    def _orphans(self, names: set, areas: set):
        def claim(files, ok, what):
            for p in files:
                if not ok(p):
                    self.err(self.rel(p), "-", f"{what} of no registered capability")
        spec = self.repo / "spec"
        lower_areas = {a.lower() for a in areas}
        for sub in ("requirements", "parameters"):
            claim(sorted((spec / sub).glob("*.yaml")), lambda p: p.stem in lower_areas, sub[:-1])
        claim(sorted((spec / "justifications").glob("*.yaml")), lambda p: p.stem in names, "justification")
        claim(sorted((spec / "schemas").glob("vectors_*.schema.json")),
              lambda p: p.name[len("vectors_"):-len(".schema.json")] in names, "vector schema")
        models = {m.name for m in self.reg.models}
        claim(sorted((self.repo / "models").glob("*.pml")), lambda p: p.stem in models, "model")
        # shared parts of a capability's models: models/include/<cap>_*.pml
        claim(sorted((self.repo / "models" / "include").glob("*")),
              lambda p: p.suffix == ".pml" and p.stem.split("_")[0] in names and "_" in p.stem,
              "shared model part (models/include/<cap>_*.pml)")
        claim(sorted(p for p in (self.repo / "proofs").glob("*") if p.is_dir()),
              lambda p: p.name in names, "proof folder")
        for kind in ("runtime", "offline"):
            claim(sorted(p for p in (self.repo / "cpp" / kind).glob("*") if p.is_dir()),
                  lambda p, k=kind: p.name in names or p.name in SHARED[k], f"cpp/{kind} module")
        part_dir = self.repo / "testgen" / "railproof_testgen" / "capabilities"
        claim(sorted(p for p in part_dir.glob("*.py") if p.stem != "__init__"),
              lambda p: p.stem in names, "testgen capability part")


def cmake_text(reg: Registry) -> str:
    """CMake variables for the build (cpp/CMakeLists.txt, cmake/RailproofPipeline.cmake)."""
    out = ["# Generated from spec/capabilities.yaml by railproof_testgen registry. Do not edit.",
           f"set(RAILPROOF_CAPABILITIES {' '.join(c.name for c in reg.capabilities)})"]
    for c in reg.fault_owners:
        p = f"RAILPROOF_CAP_{c.name}"
        out += [f"set({p}_AREAS {' '.join(c.areas)})",
                f"set({p}_MODELS {' '.join(m.name for m in c.models)})",
                f"set({p}_PARTS {' '.join(c.parts)})",
                f"set({p}_CONFORMANCE {'ON' if c.conformance else 'OFF'})",
                f"set({p}_PROOFS {'ON' if c.proofs else 'OFF'})",
                f"set({p}_FAULTS {' '.join(x.id for x in c.faults)})",
                f"set({p}_FAULTS_VECTORS {' '.join(x.id for x in c.faults if 'vectors' in x.killed_by)})",
                f"set({p}_FAULTS_UNIT {' '.join(x.id for x in c.faults if 'unit' in x.killed_by)})",
                f"set({p}_STUDIES {' '.join(c.studies)})"]
    return "\n".join(out) + "\n"


def faults_header(reg: Registry) -> str:
    """The seeded-fault identifiers for the mutant-schemata build (railproof/core/seeded_fault.hpp)."""
    ids = [x.id for c in reg.fault_owners for x in c.faults]
    lines = ["// Generated from spec/capabilities.yaml by railproof_testgen registry. Do not edit.",
             "// The seeded faults of every capability (railproof/core/seeded_fault.hpp).",
             "#pragma once", "", "#include <array>", "#include <cstdint>", "#include <string_view>", "",
             "namespace railproof::core {", "",
             "enum class SeededFault : std::uint16_t {"]
    lines += [f"  {i}," for i in ids]
    lines += ["};", "",
              f"inline constexpr std::array<std::string_view, {len(ids)}> kSeededFaultNames{{"]
    lines += [f'    "{i}",' for i in ids]
    lines += ["};", "", "}  // namespace railproof::core"]
    return "\n".join(lines) + "\n"


def run(args) -> int:
    reg = load(Path(args.spec))
    if args.check:
        errors = Checker(reg, Path(args.repo)).run()
        for e in errors:
            print(e, file=sys.stderr)
        if errors:
            print(f"registry: {len(errors)} error(s)", file=sys.stderr)
            return 1
        print(f"registry: {len(reg.capabilities)} capabilities agree with the tree "
              f"({', '.join(c.name for c in reg.capabilities)})")
    if args.cmake:
        write_atomic(Path(args.cmake), cmake_text(reg))
    if args.faults_header:
        write_atomic(Path(args.faults_header), faults_header(reg))
    if args.json:
        data = {"schema": "railproof/registry/1", "capabilities": [
            {"name": c.name, "title": c.title, "sources": c.sources, "areas": c.areas,
             "models": [{"name": m.name, "path": m.path, "configurations": m.configurations} for m in c.models],
             "design": c.design, "chapter": c.chapter, "runtime_parts": c.parts,
             "conformance": c.conformance, "proofs": c.proofs, "studies": c.studies,
             "faults": [{"id": x.id, "text": x.text, "killed_by": x.killed_by} for x in c.faults]}
            for c in reg.capabilities],
            "units": {"name": "units", "title": reg.units.title if reg.units else "",
                      "faults": [{"id": x.id, "text": x.text, "killed_by": x.killed_by}
                                 for x in (reg.units.faults if reg.units else [])]}}
        write_atomic(Path(args.json), json.dumps(data, indent=2, sort_keys=True) + "\n")
    return 0


def register(sub):
    add_command(sub, "registry", run,
                "check the capability registry against the tree and write what the build reads from it",
                spec=SPEC_DIR, repo={"default": ".", "help": "repository root"},
                check={"action": "store_true", "help": "check the registry against the tree"},
                cmake={"help": "write the CMake variables here"},
                faults_header={"help": "write the seeded-fault identifiers (C++) here"},
                json={"help": "write the registry as JSON (for the evidence)"})
