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

import sys
from pathlib import Path

from . import SPEC_DIR, add_command
from . import lines as lines_mod
from . import spec as spec_mod
from . import timetables as timetables_mod
from . import trains as trains_mod
from .checks import (ASM_ID, CITATION, HAZ_ID, ID_TOKEN, KIND_WORD, KINDS, PREFIX_KIND, REQ_ID,
                     UR_ID, Report, check_data_files, check_sources, label, listing,
                     load_schema, missing_data, raise_first, schema_errors)
from .errors import SpecError

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
                         + listing(r["id"] for r in line["running_lines"]) + ")")
            return
        names = [s["name"] for s in rl["stations"]]
        known, listed = set(names), listing(names)
        for i, t in enumerate(data["trains"]):
            for k, stop in enumerate(t.get("stops") or []):
                if stop["station"] not in known:
                    report.error(f, f"{label('trains', t, i)}.stops[{k}]",
                                 f"station: unknown station {stop['station']!r} on running line "
                                 f"{rl['id']} (has: {listed})")
        routes = {r["id"] for r in rl["routes"]}
        siding = any(r["reverse"] and not r["automatic"] for r in rl["routes"])
        for i, fault in enumerate(data.get("faults") or []):
            if fault["type"] != "siding_request":
                continue
            if "route" in fault and fault["route"] not in routes:
                report.error(f, f"faults[{i}]", f"route: unknown route {fault['route']} on running "
                                                f"line {rl['id']}")
            elif "route" not in fault and not siding:
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
            schema = spec_mod.load_json(path).get("schema")
        except SpecError as exc:
            report.error(exc.file, exc.entry, exc.reason)
            continue
        kind = _DATA_CHECKS.get(schema) if isinstance(schema, str) else None
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
    return PREFIX_KIND[prefix], {"REQ": REQ_ID, "HAZ": HAZ_ID, "ASM": ASM_ID, "UR": UR_ID}[prefix]


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
            validator = load_schema(spec_dir, schema_name)
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
            schema_errors(validator, data, f, report)
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
    line_outputs, line_refs = lines_mod.check_lines(spec_dir, report)
    model["lines"] = line_outputs
    refs.extend(line_refs)
    # Train types (spec/trains, REQ-BR-010): schema, ranges and the pattern design rule.
    train_outputs, train_refs = trains_mod.check_trains(spec_dir, report)
    model["trains"] = {name: obj for (_m, name), obj in train_outputs.items()}
    refs.extend(train_refs)
    # Timetables (spec/timetables, REQ-LC-017) against those lines and train types; the
    # hand-written JSON data of the simulators (spec/scenarios, spec/wheelrail).
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
                report.error(f, eid, f"{where}: unknown {KIND_WORD[kind]} {token}")


def _check_requirements(model, report):
    for rid, r in sorted(model["requirements"].items()):
        f = r["file"]
        sil = r.get("sil")
        ver = r.get("verification")
        if isinstance(sil, int) and not isinstance(sil, bool) and sil >= 3 \
                and isinstance(ver, list) and ver and all(v == "review" for v in ver):
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
