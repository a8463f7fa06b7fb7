"""Specification checker: JSON-Schema validation of spec/ plus semantic cross-checks.

Command ``validate --spec DIR`` checks every YAML file of
``spec/{requirements,hazards,assumptions,parameters,justifications}`` against the
Draft 2020-12 schemas in ``spec/schemas/``, then the cross-references the schemas cannot
express. It also checks the data files, each against its schema and then what the schema
cannot say (what a file names in the others): the lines (``lines.py``), the train types
(``trains.py``), the timetables (``timetables.py``), the line scenarios
``spec/scenarios/*.json`` and the wheel-rail scenarios ``spec/wheelrail/*.json`` (below);
the assumptions and requirements they name must exist. It collects every finding, prints
each as one line ``file: entry: reason`` and exits 1 if there is any error (warnings alone
do not fail).

Rules checked after the schema:
- IDs are unique within and across files (requirements, hazards, assumptions,
  justifications; parameter ids within a file, both sections together), and a
  requirement's ``REQ-<AREA>-NNN`` area is the file's ``area``;
- no two parameter files declare the same area (their generated headers would collide);
- a requirement with SIL >= 3 is not verified by ``review`` alone;
- every ``REQ-…``, ``HAZ-…``, ``ASM-…`` or ``UR-…`` token in any string of any entry
  (``hazards``, ``source``, parameter ``requirements``, text, rationale) names an existing
  entry; a token that looks like an ID but is malformed is an error too;
- every hazard is addressed by at least one requirement.  This is an error, not a warning:
  an unaddressed hazard is an open item in the hazard log, and the safety case cannot be
  closed over it; the fix is either a requirement that mitigates it or removing the hazard
  with a recorded reason;
- every requirement ``source`` entry and every parameter ``source`` cites D1-D5 with a
  section (``D5 §6.4``, ``D1 chapter 3``), an assumption ``ASM-NNN`` or a named standard
  (``EN 50159``, ``IEC 62280``, ``RFC 8439``...).

Warnings: an assumption that nothing references; a SIL >= 3 requirement naming no hazard.
"""
from __future__ import annotations

import json
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

import jsonschema

from . import SPEC_DIR, add_command
from . import spec as spec_mod
from .errors import SpecError

AREAS = ("TG", "MB", "BR", "SC", "RA", "LC", "GN", "FC", "AV")
METHODS = ("model", "vectors", "unit", "analysis", "proof", "review")
_AREA_RE = "|".join(AREAS)
REQ_ID = re.compile(rf"^REQ-({_AREA_RE})-\d{{3}}$")
HAZ_ID = re.compile(r"^HAZ-\d{3}$")
ASM_ID = re.compile(r"^ASM-\d{3}$")
UR_ID = re.compile(rf"^UR-({_AREA_RE})-\d{{3}}$")

# Anything that looks like an identifier of ours inside free text.
ID_TOKEN = re.compile(r"\b(?:REQ|HAZ|ASM|UR)-[A-Za-z0-9]+(?:-[A-Za-z0-9]+)*")

# A source citation: D1-D5 with a section or chapter, an assumption, or a named standard.
CITATION = re.compile(
    r"\bD[1-5]\s*(?:§\s*\d|chapters?\s+\d)"
    r"|\bD3\b"  # D3 is a short article without numbered sections (digest §5)
    r"|\bASM-\d{3}\b"
    r"|\b(?:EN|IEC|ISO|IEEE|UIC|DIN|RFC|FIPS|CLC/TS|CLC/TR|ISO/IEC|NIST\s+SP)\s*[-:]?\s*\d"
    r"|\bMISRA\b")

# kind -> (sub-directory of spec/, list key, schema file, id pattern)
KINDS = {
    "requirements": ("requirements", "requirements", "requirements.schema.json", REQ_ID),
    "hazards": ("hazards", "hazards", "hazards.schema.json", HAZ_ID),
    "assumptions": ("assumptions", "assumptions", "assumptions.schema.json", ASM_ID),
    "justifications": ("justifications", "justifications", "justifications.schema.json", UR_ID),
    "parameters": ("parameters", None, "parameters.schema.json", None),
}
_PREFIX_KIND = {"REQ": "requirements", "HAZ": "hazards", "ASM": "assumptions",
                "UR": "justifications"}
_KIND_WORD = {"requirements": "requirement", "hazards": "hazard",
              "assumptions": "assumption", "justifications": "justification"}


@dataclass(frozen=True, order=True)
class Finding:
    """One reported problem: ``file: entry: reason``."""

    file: str
    entry: str
    reason: str

    def __str__(self):
        return f"{self.file}: {self.entry}: {self.reason}"


@dataclass
class Report:
    """Collects errors and warnings; nothing stops at the first finding."""

    errors: list = field(default_factory=list)
    warnings: list = field(default_factory=list)

    def error(self, file, entry, reason):
        f = Finding(str(file), str(entry), str(reason))
        if f not in self.errors:
            self.errors.append(f)
        return f

    def warn(self, file, entry, reason):
        f = Finding(str(file), str(entry), str(reason))
        if f not in self.warnings:
            self.warnings.append(f)
        return f

    def print(self, stream=None):
        stream = stream or sys.stderr
        for w in self.warnings:
            print(f"warning: {w}", file=stream)
        for e in self.errors:
            print(e, file=stream)


_VALIDATORS = {}  # schema text -> validator (checking a schema against the meta-schema is slow)


def _load_schema(spec_dir: Path, name: str):
    path = Path(spec_dir) / "schemas" / name
    try:
        text = path.read_text(encoding="utf-8")
        if text in _VALIDATORS:
            return _VALIDATORS[text]
        schema = json.loads(text)
    except FileNotFoundError:
        raise SpecError(path, "-", "schema file not found") from None
    except json.JSONDecodeError as exc:
        raise SpecError(path, f"line {exc.lineno}", f"malformed JSON: {exc.msg}") from None
    try:
        jsonschema.Draft202012Validator.check_schema(schema)
    except jsonschema.SchemaError as exc:
        raise SpecError(path, "/".join(map(str, exc.path)) or "-",
                        f"invalid schema: {exc.message}") from None
    _VALIDATORS[text] = jsonschema.Draft202012Validator(schema)
    return _VALIDATORS[text]


def _entry_name(data, path):
    """Human name of the entry a schema error points at: its id if it has one."""
    if not path:
        return "-", ""
    head = path[0]
    if len(path) >= 2 and isinstance(path[1], int):
        lst = data.get(head) if isinstance(data, dict) else None
        item = lst[path[1]] if isinstance(lst, list) and path[1] < len(lst) else None
        name = item.get("id") if isinstance(item, dict) else None
        name = name if isinstance(name, str) and name else f"{head}[{path[1]}]"
        rest = ".".join(str(p) if not isinstance(p, int) else f"[{p}]" for p in path[2:])
        return name, rest.replace(".[", "[")
    return str(head), ".".join(str(p) for p in path[1:])


def _schema_errors(validator, data, file, report, entry_of=_entry_name):
    """Report every schema error as ``file: entry: where: message`` (the entry named by
    entry_of(data, path)); returns their number."""
    n = 0
    for err in sorted(validator.iter_errors(data), key=lambda e: [str(p) for p in e.path]):
        entry, where = entry_of(data, list(err.path))
        report.error(file, entry, f"{where}: {err.message}" if where else err.message)
        n += 1
    return n


def label(section, item, index):
    """Entry name of item `index` of list `section`: ``section[<id or name>]``, else the index."""
    if isinstance(item, dict):
        for key in ("id", "name"):
            v = item.get(key)
            if isinstance(v, (str, int)) and not isinstance(v, bool) and v != "":
                return f"{section}[{v}]"
    return f"{section}[{index}]"


def _schema_entry(data, path):
    """(entry, where) for a schema error at `path` inside `data` (data files: lists of
    entries are named by label(), nested lists too, e.g. ``stations[S1].platforms[P2]``)."""
    if not path:
        return "-", ""
    entry, node, rest = [], data, list(path)
    consumed = 0
    i = 0
    while i < len(rest):
        key = rest[i]
        nxt = rest[i + 1] if i + 1 < len(rest) else None
        if isinstance(key, str) and isinstance(nxt, int) and isinstance(node, dict) \
                and isinstance(node.get(key), list):
            lst = node[key]
            item = lst[nxt] if nxt < len(lst) else None
            entry.append(label(key, item, nxt))
            node = item
            i += 2
            consumed = i
            continue
        break
    if not entry:
        return str(rest[0]), ".".join(str(p) for p in rest[1:])
    return ".".join(entry), ".".join(str(p) for p in rest[consumed:])


def data_schema_errors(validator, data, file, report):
    """The schema errors of a data file (lines, trains, timetables, scenarios), entries
    named by label()."""
    return _schema_errors(validator, data, file, report, _schema_entry)


def check_data_files(spec_dir, files, schema_name, report, check, load=spec_mod.load_yaml):
    """The one loop over the data files of spec/: load each file, check it against
    spec/schemas/<schema_name>, and call check(file, data) for every schema-valid file.
    Nothing stops at the first finding."""
    if not files:
        return
    try:
        validator = _load_schema(spec_dir, schema_name)
    except SpecError as exc:
        report.error(exc.file, exc.entry, exc.reason)
        return
    for f in files:
        try:
            data = load(f)
        except SpecError as exc:
            report.error(exc.file, exc.entry, exc.reason)
            continue
        if data_schema_errors(validator, data, f, report):
            continue
        check(f, data)


def check_sources(report, file, entry, sources):
    """Every source string cites D1-D5 with a section, an ASM-NNN or a named standard;
    returns False if one does not."""
    ok = True
    for i, s in enumerate(sources):
        if isinstance(s, str) and not CITATION.search(s):
            report.error(file, entry, f"source[{i}] {s!r} cites no D1-D5 section, ASM-NNN or "
                                      "named standard")
            ok = False
    return ok


def provenance_refs(file, name, data):
    """(file, entry, field, text) of a data file's assumption and sources, for the check
    that the assumptions they name exist."""
    refs = [(file, name, "assumption", data["assumption"])] if "assumption" in data else []
    refs.extend((file, name, f"source[{i}]", s) for i, s in enumerate(data.get("source") or []))
    return refs


def known_assumptions(spec_dir, report):
    """Ids of spec/assumptions, or None if a file cannot be read (reported)."""
    ids = set()
    for f in spec_mod.spec_files(spec_dir, "assumptions"):
        try:
            data = spec_mod.load_yaml(f)
        except SpecError as exc:
            report.error(exc.file, exc.entry, exc.reason)
            return None
        for e in data.get("assumptions") or []:
            if isinstance(e, dict) and isinstance(e.get("id"), str):
                ids.add(e["id"])
    return ids


def check_assumption_refs(spec_dir, refs, report):
    """Every ASM-NNN named by a data file must exist in spec/assumptions (used by the
    single-kind commands lines, trains and timetables; validate checks every kind of
    reference)."""
    known = known_assumptions(spec_dir, report)
    if known is None:
        return
    for f, entry, where, s in refs:
        for token in ID_TOKEN.findall(s):
            if token.startswith("ASM-") and ASM_ID.match(token) and token not in known:
                report.error(f, entry, f"{where}: unknown assumption {token}")
            elif token.startswith("ASM-") and not ASM_ID.match(token):
                report.error(f, entry, f"{where}: malformed reference {token!r}")


def missing_data(spec_dir, sub, name, what):
    """Reason for a name that no valid file of spec/<sub> defines."""
    path = Path(spec_dir) / sub / f"{name}.yaml"
    if path.exists():
        return f"{what} {name!r} has errors ({sub}/{path.name}, reported by validate)"
    return f"unknown {what} {name!r} (no {sub}/{path.name})"


def checked_directory(spec_dir, sub, what, check, found):
    """(outputs, report) of the data directory spec/<sub> (what: "line", "train type"): an
    error if it is missing; else check(spec_dir, report) -> (outputs, refs), an error if
    found(outputs) says it holds no file of its kind, and the assumption references."""
    report = Report()
    spec_dir = Path(spec_dir)
    if not (spec_dir / sub).is_dir():
        report.error(spec_dir / sub, "-", f"{what} directory not found")
        return {}, report
    outputs, refs = check(spec_dir, report)
    if not found(outputs) and not report.errors:
        report.error(spec_dir / sub, "-", f"no {what} files (*.yaml)")
    check_assumption_refs(spec_dir, refs, report)
    return outputs, report


def convert(command, args, build, describe, path_of=lambda name: f"{name}.json"):
    """Run a converting command (lines, trains, timetables: spec/<command> -> OUT): print the
    findings of build(spec_dir) -> (outputs, report); on an error a summary line, nothing
    written and exit status 1; else each output written as JSON to OUT/path_of(key), with
    the line "<command>: describe(key, output, path)"."""
    spec_dir, out_dir = Path(args.spec), Path(args.out)
    outputs, report = build(spec_dir)
    report.print()
    if report.errors:
        print(f"{command}: {len(report.errors)} error(s) in {spec_dir / command}; nothing written",
              file=sys.stderr)
        return 1
    for key, obj in sorted(outputs.items()):
        path = out_dir / path_of(key)
        spec_mod.write_atomic(path, spec_mod.render_json(obj))
        print(f"{command}: {describe(key, obj, path)}")
    return 0


def raise_first(report):
    """Raise the report's first error as SpecError, with the count of the others."""
    if report.errors:
        first, more = report.errors[0], len(report.errors) - 1
        raise SpecError(first.file, first.entry,
                        first.reason + (f" (and {more} more)" if more else ""))


def _check_file_name(report, f, data):
    if data["name"] != f.stem:
        report.error(f, "name", f"{data['name']!r} must equal the file name {f.stem!r}")


def check_scenarios(spec_dir, report, lines, files=None):
    """spec/scenarios/*.json (line_sim), or the given files: the schema, then what it
    cannot say: the name is the file name (of spec/scenarios), the line is a valid line of spec/lines with the running line, every stop
    names a station of that running line, and a siding request names a route of it (none
    named: the running line has a reverse, non-automatic route). The rules within the file
    (ordering, windows, train ids) are the simulator's (spec/design/data.md)."""
    out, own = {}, files is None

    def check(f, data):
        if own:
            _check_file_name(report, f, data)
        line = lines.get(data["line"])
        if line is None:
            report.error(f, "line", missing_data(spec_dir, "lines", data["line"], "line"))
            return
        rl = next((r for r in line["running_lines"] if r["id"] == data["running_line"]), None)
        if rl is None:
            report.error(f, "running_line", f"unknown running line {data['running_line']!r} on "
                         f"line {line['name']} (has: "
                         + ", ".join(r["id"] for r in line["running_lines"]) + ")")
            return
        names = [s["name"] for s in rl["stations"]]
        for i, t in enumerate(data["trains"]):
            for k, stop in enumerate(t.get("stops") or []):
                if stop["station"] not in names:
                    report.error(f, f"{label('trains', t, i)}.stops[{k}]",
                                 f"station: unknown station {stop['station']!r} on running line "
                                 f"{rl['id']} (has: {', '.join(names)})")
        for i, fault in enumerate(data.get("faults") or []):
            if fault["type"] != "siding_request":
                continue
            if "route" in fault and not any(r["id"] == fault["route"] for r in rl["routes"]):
                report.error(f, f"faults[{i}]", f"route: unknown route {fault['route']} on running "
                                                f"line {rl['id']}")
            elif "route" not in fault and not any(r["reverse"] and not r["automatic"]
                                                  for r in rl["routes"]):
                report.error(f, f"faults[{i}]", f"running line {rl['id']} has no siding "
                                                "(reverse, non-automatic) route")
        out[data["name"]] = data

    if own:
        files = sorted((Path(spec_dir) / "scenarios").glob("*.json"))
    check_data_files(spec_dir, files, "scenario.schema.json", report, check,
                     load=spec_mod.load_json)
    return out


def check_wheelrail(spec_dir, report, files=None):
    """spec/wheelrail/*.json (wheelrail_sim, odometry_study), or the given files: the
    schema, then what it cannot say: the name is the file name (of spec/wheelrail) and
    every requirement named exists (returned as
    references for the caller's check). The rules within the file (ordering, the vertical
    curves fitting, the car inside the alignment) are the simulator's."""
    out, refs, own = {}, [], files is None

    def check(f, data):
        if own:
            _check_file_name(report, f, data)
        refs.extend((f, data["name"], f"requirements[{i}]", r)
                    for i, r in enumerate(data["requirements"]))
        out[data["name"]] = data

    if own:
        files = sorted((Path(spec_dir) / "wheelrail").glob("*.json"))
    check_data_files(spec_dir, files, "wheelrail_scenario.schema.json", report, check,
                     load=spec_mod.load_json)
    return out, refs


# The hand-written data files that `validate --data FILE` checks, by the schema they name.
_DATA_CHECKS = {"railproof/scenario/1": "scenarios", "railproof/wheelrail-scenario/1": "wheelrail"}


def _check_data_args(spec_dir, paths, model, refs, report):
    """Files given on the command line (a scenario written by hand for line_sim or
    wheelrail_sim): the same checks as the spec's own, but for the file name."""
    for path in map(Path, paths):
        try:
            kind = _DATA_CHECKS.get(spec_mod.load_json(path).get("schema"))
        except SpecError as exc:
            report.error(exc.file, exc.entry, exc.reason)
            continue
        if kind is None:
            report.error(path, "schema", "not one of " + ", ".join(sorted(_DATA_CHECKS)))
        elif kind == "scenarios":
            model[kind].update(check_scenarios(spec_dir, report, model["lines"], [path]))
        else:
            out, more = check_wheelrail(spec_dir, report, [path])
            model[kind].update(out)
            refs.extend(more)


def _strings(obj, where=""):
    """Yield (field path, string) for every string inside obj."""
    if isinstance(obj, str):
        yield where, obj
    elif isinstance(obj, dict):
        for k, v in obj.items():
            yield from _strings(v, f"{where}.{k}" if where else str(k))
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from _strings(v, f"{where}[{i}]")


def _id_pattern(token):
    prefix = token.split("-", 1)[0]
    return _PREFIX_KIND[prefix], {"REQ": REQ_ID, "HAZ": HAZ_ID, "ASM": ASM_ID, "UR": UR_ID}[prefix]


def _list_files(spec_dir: Path, sub: str, report: Report):
    for bad in sorted((Path(spec_dir) / sub).glob("*.yml")):
        report.error(bad, "-", "use the .yaml extension (files named *.yml are not read)")
    return spec_mod.spec_files(spec_dir, sub)


def check_spec(spec_dir, data_files=()):
    """Check spec_dir completely, and the data files `data_files` (paths) against it. Returns
    (model, report); model is built from the entries that could be read even when the
    report has errors."""
    spec_dir = Path(spec_dir)
    report = Report()
    if not spec_dir.is_dir():
        report.error(spec_dir, "-", "spec directory not found")
        return _empty_model(), report
    model = _empty_model()
    origin = {}  # id -> file, for duplicate messages
    refs = []  # (file, entry id, field, token) for the cross-reference pass
    param_areas = {}

    for kind, (sub, key, schema_name, id_re) in KINDS.items():
        try:
            validator = _load_schema(spec_dir, schema_name)
        except SpecError as exc:
            report.error(exc.file, exc.entry, exc.reason)
            continue
        files = _list_files(spec_dir, sub, report)
        if not files and kind in ("requirements", "hazards", "parameters"):
            report.error(spec_dir / sub, "-", f"no {kind} files (*.yaml)")
        for f in files:
            try:
                data = spec_mod.load_yaml(f)
            except SpecError as exc:
                report.error(exc.file, exc.entry, exc.reason)
                continue
            _schema_errors(validator, data, f, report)
            if kind == "parameters":
                _collect_parameters(f, data, model, param_areas, refs, report)
                continue
            area = data.get("area") if isinstance(data.get("area"), str) else None
            entries = data.get(key)
            if not isinstance(entries, list):
                continue
            for i, e in enumerate(entries):
                if not isinstance(e, dict) or not isinstance(e.get("id"), str):
                    continue  # already reported by the schema
                eid = e["id"]
                if not id_re.match(eid):
                    continue  # reported by the schema (pattern)
                if eid in origin:
                    report.error(f, eid, f"duplicate id (first defined in {origin[eid]})")
                    continue
                origin[eid] = f
                if kind == "requirements" and area and eid.split("-")[1] != area:
                    report.error(f, eid, f"id area {eid.split('-')[1]} does not match the "
                                         f"file's area {area}")
                entry = dict(e)
                entry["file"] = str(f)
                if kind == "requirements":
                    entry["area"] = eid.split("-")[1]
                model[kind][eid] = entry
                for where, s in _strings({k: v for k, v in e.items() if k != "id"}):
                    refs.append((f, eid, where, s))

    # Line data (spec/lines, REQ-MB-020): schema and topology rules; the lines' assumption
    # and source strings join the cross-reference check below.
    from . import lines as lines_mod  # imported here: lines builds on this module
    line_outputs, line_refs = lines_mod.check_lines(spec_dir, report)
    model["lines"] = line_outputs
    refs.extend(line_refs)
    # Train types (spec/trains, REQ-BR-010): schema, ranges and the pattern design rule.
    from . import trains as trains_mod
    train_outputs, train_refs = trains_mod.check_trains(spec_dir, report)
    model["trains"] = {name: obj for (_m, name), obj in train_outputs.items()}
    refs.extend(train_refs)
    # Timetables (spec/timetables, REQ-LC-017) against those lines and train types; the
    # hand-written JSON data of the simulators (spec/scenarios, spec/wheelrail).
    from . import timetables as timetables_mod
    model["timetables"], tt_refs = timetables_mod.check_timetables(
        spec_dir, report, model["lines"], model["trains"])
    refs.extend(tt_refs)
    model["scenarios"] = check_scenarios(spec_dir, report, model["lines"])
    model["wheelrail"], wr_refs = check_wheelrail(spec_dir, report)
    refs.extend(wr_refs)
    _check_data_args(spec_dir, data_files, model, refs, report)

    _check_references(model, refs, report)
    _check_requirements(model, report)
    _check_hazards_addressed(model, report)
    _check_assumptions_used(model, refs, report)
    return model, report


def _empty_model():
    return {"requirements": {}, "hazards": {}, "assumptions": {}, "justifications": {},
            "parameters": {}, "lines": {}, "trains": {}, "timetables": {}, "scenarios": {},
            "wheelrail": {}}


def _collect_parameters(f, data, model, param_areas, refs, report):
    area = data.get("area")
    if isinstance(area, str):
        if area in param_areas:
            report.error(f, "area", f"area {area} is also declared by {param_areas[area]}; "
                                    "one parameter file per area")
            return
        param_areas[area] = f
    else:
        area = None
    out = {"file": f, "parameters": {}, "model_bounds": {}}
    seen = {}
    for section in ("parameters", "model_bounds"):
        entries = data.get(section)
        if not isinstance(entries, list):
            continue
        for e in entries:
            if not isinstance(e, dict) or not isinstance(e.get("id"), str):
                continue
            pid = e["id"]
            if pid in seen:
                report.error(f, pid, f"duplicate parameter id (also in {seen[pid]})")
                continue
            seen[pid] = section
            v = e.get("value")
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                continue  # reported by the schema
            out[section][pid] = e
            if section == "parameters" and isinstance(e.get("source"), str) \
                    and not CITATION.search(e["source"]):
                report.error(f, pid, f"source {e['source']!r} cites no D1-D5 section, "
                                     "ASM-NNN or named standard")
            for where, s in _strings({k: v for k, v in e.items() if k != "id"}):
                refs.append((f, pid, where, s))
    if area:
        model["parameters"][area] = out


def _check_references(model, refs, report):
    for f, eid, where, s in refs:
        for token in ID_TOKEN.findall(s):
            kind, pattern = _id_pattern(token)
            if not pattern.match(token):
                report.error(f, eid, f"{where}: malformed reference {token!r}")
            elif token not in model[kind]:
                report.error(f, eid, f"{where}: unknown {_KIND_WORD[kind]} {token}")


def _check_requirements(model, report):
    for rid, r in sorted(model["requirements"].items()):
        f = r["file"]
        sil = r.get("sil")
        ver = r.get("verification")
        if isinstance(sil, int) and not isinstance(sil, bool) and sil >= 3 \
                and isinstance(ver, list) and set(ver) == {"review"}:
            report.error(f, rid, f"SIL {sil} requirement verified by review alone; "
                                 "add model, vectors, unit, analysis or proof")
        if isinstance(r.get("source"), list):
            check_sources(report, f, rid, r["source"])
        if isinstance(sil, int) and sil >= 3 and r.get("hazards") == []:
            report.warn(f, rid, f"SIL {sil} requirement names no hazard")


def _check_hazards_addressed(model, report):
    addressed = set()
    for r in model["requirements"].values():
        if isinstance(r.get("hazards"), list):
            addressed.update(h for h in r["hazards"] if isinstance(h, str))
    for hid, h in sorted(model["hazards"].items()):
        if hid not in addressed:
            report.error(h["file"], hid, "hazard is not addressed by any requirement")


def _check_assumptions_used(model, refs, report):
    used = set()
    for _f, eid, _where, s in refs:
        used.update(t for t in ID_TOKEN.findall(s) if t.startswith("ASM-") and t != eid)
    for aid, a in sorted(model["assumptions"].items()):
        if aid not in used:
            report.warn(a["file"], aid, "assumption is not referenced by any requirement, "
                                        "hazard, parameter or other assumption")


def validate_spec(spec_dir):
    """Validate spec_dir and return the loaded model::

        {"requirements": {id: entry + {"file", "area"}},
         "hazards": {id: entry + {"file"}}, "assumptions": {...}, "justifications": {...},
         "parameters": {area: {"file": Path, "parameters": {id: entry},
                               "model_bounds": {id: entry}}}}

    Raises SpecError naming the first error, with "(and N more)" if there are more.
    """
    model, report = check_spec(spec_dir)
    raise_first(report)
    return model


def run(args):
    model, report = check_spec(Path(args.spec), args.data)
    report.print()
    n = {k: len(v) for k, v in model.items()}
    if report.errors:
        print(f"validate: {len(report.errors)} error(s), {len(report.warnings)} warning(s) "
              f"in {args.spec}", file=sys.stderr)
        return 1
    print(f"validate: {args.spec} ok: {n['requirements']} requirements, {n['hazards']} hazards, "
          f"{n['assumptions']} assumptions, {n['parameters']} parameter file(s), "
          f"{n['justifications']} justifications, {n['lines']} line(s), "
          f"{n['trains']} train type(s), {n['timetables']} timetable(s), "
          f"{n['scenarios']} scenario(s), {n['wheelrail']} wheel-rail scenario(s); "
          f"{len(report.warnings)} warning(s)")
    return 0


def register(sub):
    add_command(sub, "validate", run, "check spec/ against its JSON schemas and cross-references",
                """Validate every file of
                spec/{requirements,hazards,assumptions,parameters,justifications,lines,trains,timetables}
                (YAML) and spec/{scenarios,wheelrail} (JSON) against spec/schemas and check
                IDs, references, the line topology rules and what each data file names in the
                others. Prints every finding as 'file: entry: reason'; exit 1 on any
                error.""",
                spec=SPEC_DIR,
                data={"action": "append", "default": [], "metavar": "FILE",
                      "help": "also check this scenario or wheel-rail scenario JSON (for example one "
                              "written by hand for line_sim or wheelrail_sim) against the spec; "
                              "repeatable"})
