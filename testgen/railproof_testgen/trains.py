"""Train types: validation of spec/trains/*.yaml and generation of the train JSON.

Command ``trains --spec DIR --out DIR`` checks every ``spec/trains/*.yaml`` (and the
deliberately weakened negative-test types of ``spec/trains/mutants/*.yaml``) against
``spec/schemas/train.schema.json`` and the rules below, then writes ``OUT/<name>.json``
and ``OUT/mutants/<name>.json`` (schema ``railproof/train-json/1``: the YAML's keys and
integer values, read by the C++ margin verification and the speed-check design tool).
Every finding is one line ``file: entry: reason``; with any error nothing is written and
the exit status is 1. ``validate --spec`` runs the same checks on spec/trains/*.yaml.

Rules after the schema:
- ``name`` is the file name; every source cites D1-D5 §, an ASM or a standard; the
  ``assumption`` exists;
- every range ``[min, max]`` has min <= max;
- design rule of the pattern decelerations (REQ-BR-010): the service pattern deceleration
  does not exceed the emergency pattern deceleration, which does not exceed the lowest
  real emergency deceleration. A negative-test type in ``mutants/`` may break this rule
  (that is its purpose); its JSON lists the broken rules under ``design_rule_violations``
  and the margin verification must fail on it.
"""
from __future__ import annotations

from pathlib import Path

from . import SPEC_DIR, add_command
from . import checks

SUB = "trains"
MUTANTS = "mutants"
SCHEMA_FILE = "train.schema.json"
JSON_SCHEMA = "railproof/train-json/1"

_RANGES = (("braking", "emergency_free_running_ms"), ("braking", "service_free_running_ms"),
           ("uncertainty", "emergency_deceleration_mm_s2"),
           ("uncertainty", "service_deceleration_mm_s2"))


def design_rule_violations(data):
    """Broken pattern-deceleration rules of REQ-BR-010 (list of reasons)."""
    b, u = data["braking"], data["uncertainty"]
    out = []
    if b["service_pattern_mm_s2"] > b["emergency_pattern_mm_s2"]:
        out.append(f"service pattern deceleration {b['service_pattern_mm_s2']} mm/s^2 exceeds "
                   f"the emergency pattern deceleration {b['emergency_pattern_mm_s2']} mm/s^2 "
                   "(REQ-BR-010)")
    lowest = u["emergency_deceleration_mm_s2"][0]
    if b["emergency_pattern_mm_s2"] > lowest:
        out.append(f"emergency pattern deceleration {b['emergency_pattern_mm_s2']} mm/s^2 exceeds "
                   f"the lowest real emergency deceleration {lowest} mm/s^2 (REQ-BR-010)")
    return out


def _check(f, data, report, mutant):
    name = data["name"]
    ok = True
    if name != f.stem:
        report.error(f, name, f"name {name!r} must equal the file name {f.stem!r}")
        ok = False
    if not checks.check_sources(report, f, name, data["source"]):
        ok = False
    for group, key in _RANGES:
        lo, hi = data[group][key]
        if lo > hi:
            report.error(f, f"{group}.{key}", f"range [{lo}, {hi}] has min > max")
            ok = False
    broken = design_rule_violations(data)
    if not mutant:
        for reason in broken:
            report.error(f, f"{name}.braking", reason)
            ok = False
    if not ok:
        return None
    obj = dict(data)
    obj["schema"] = JSON_SCHEMA
    if mutant:
        obj["design_rule_violations"] = broken
    return obj


def check_trains(spec_dir, report, with_mutants=False):
    """Check spec/trains (and mutants/ if asked) into `report`; returns (outputs, refs):
    outputs maps (mutant, name) -> train JSON object of the files without errors."""
    spec_dir = Path(spec_dir)
    outputs, refs = {}, []
    root = spec_dir / SUB
    if not root.is_dir():
        return outputs, refs
    for mutant, files in [(False, sorted(root.glob("*.yaml")))] + \
            ([(True, sorted((root / MUTANTS).glob("*.yaml")))] if with_mutants else []):

        def check(f, data, mutant=mutant):
            refs.extend(checks.provenance_refs(f, data["name"], data))
            obj = _check(f, data, report, mutant)
            if obj is not None:
                outputs[(mutant, data["name"])] = obj

        checks.check_data_files(spec_dir, files, SCHEMA_FILE, report, check)
    return outputs, refs


def build(spec_dir):
    return checks.checked_directory(spec_dir, SUB, "train type",
                                  lambda d, report: check_trains(d, report, with_mutants=True),
                                  lambda outputs: any(not m for m, _ in outputs))


def _converted(key, obj, path):
    mutant, name = key
    return f"{'negative-test ' if mutant else ''}{name} -> {path}"


def _output_path(key):
    mutant, name = key
    return Path(MUTANTS if mutant else "") / f"{name}.json"


def run(args):
    return checks.convert(SUB, args, build, _converted, _output_path)


def register(sub):
    add_command(sub, "trains", run, "validate spec/trains and write the train JSON",
                """Check every spec/trains/*.yaml and spec/trains/mutants/*.yaml against
                spec/schemas/train.schema.json and the design rule REQ-BR-010 (not enforced
                for the negative-test types in mutants/), then write OUT/<name>.json and
                OUT/mutants/<name>.json (schema railproof/train-json/1). On any error nothing
                is written, exit 1.""",
                spec=SPEC_DIR, out="output directory (build/gen/trains)")
