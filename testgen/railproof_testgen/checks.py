"""The shared machinery of the spec checks: identifiers and citations, findings
(``file: entry: reason``) and their report, schema loading and schema findings, the data
files of spec/ (loaded, checked against their schema, then by the check of their kind),
their provenance references, and the conversion of a checked kind to the JSON the C++
reads (nothing written on any error, every output written or none: files.write_all).

The checks of each kind build on this module: the lines (``lines.py``), the train types
(``trains.py``), the timetables (``timetables.py``) and the command ``validate``
(``validate.py``), which runs them all over spec/.
"""
from __future__ import annotations

import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

import jsonschema

from . import spec as spec_mod
from .spec import label  # noqa: F401 (the entry names of the checks, shared with the loader)
from .files import write_all
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
PREFIX_KIND = {"REQ": "requirements", "HAZ": "hazards", "ASM": "assumptions",
                "UR": "justifications"}
KIND_WORD = {"requirements": "requirement", "hazards": "hazard",
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
    _seen: set = field(default_factory=set, repr=False, compare=False)  # the findings so far

    def error(self, file, entry, reason):
        return self._add(self.errors, Finding(str(file), str(entry), str(reason)))

    def warn(self, file, entry, reason):
        return self._add(self.warnings, Finding(str(file), str(entry), str(reason)))

    def _add(self, findings, f):
        """Each finding once (a set beside the list: the check of a file with many findings
        stays linear in their number)."""
        key = (findings is self.errors, f)
        if key not in self._seen:
            self._seen.add(key)
            findings.append(f)
        return f

    def print(self, stream=None):
        stream = stream or sys.stderr
        for w in self.warnings:
            print(f"warning: {w}", file=stream)
        for e in self.errors:
            print(e, file=stream)


_VALIDATORS = {}  # schema text -> validator (checking a schema against the meta-schema is slow)

def _canonical(v):
    """A hashable form of a JSON value, equal for values JSON Schema calls equal (1 and 1.0,
    not True and 1; mappings regardless of key order)."""
    if isinstance(v, bool):
        return ("b", v)
    if isinstance(v, (int, float)):
        return ("n", v)
    if isinstance(v, dict):
        return ("m", frozenset((k, _canonical(x)) for k, x in v.items()))
    if isinstance(v, list):
        return ("l", tuple(_canonical(x) for x in v))
    return ("s", v)


def _unique_items(validator, unique, instance, schema):
    """uniqueItems in time linear in the array: jsonschema compares every pair of an array
    it cannot sort (mixed types, mappings), which an array of a hundred thousand items
    makes minutes of work."""
    if not unique or not validator.is_type(instance, "array"):
        return
    seen = set()
    for item in instance:
        key = _canonical(item)
        if key in seen:
            yield jsonschema.ValidationError(f"{item!r} occurs more than once")
            return
        seen.add(key)


# The schemas' "integer" is a whole number written as one: JSON Schema counts 200.0 as an
# integer, but the generated headers and JSON would carry it as a double (a parameter would
# become `200.0`, a line field a number the C++ reader refuses as an integer).
_Validator = jsonschema.validators.extend(
    jsonschema.Draft202012Validator,
    validators={"uniqueItems": _unique_items},
    type_checker=jsonschema.Draft202012Validator.TYPE_CHECKER.redefine(
        "integer", lambda _checker, v: isinstance(v, int) and not isinstance(v, bool)))


def load_schema(spec_dir: Path, name: str):
    path = Path(spec_dir) / "schemas" / name
    if not path.exists():
        raise SpecError(path, "-", "schema file not found")
    text = spec_mod.read_text(path)
    if text in _VALIDATORS:
        return _VALIDATORS[text]
    schema = spec_mod.parse_json(path, text)
    try:
        jsonschema.Draft202012Validator.check_schema(schema)
    except jsonschema.SchemaError as exc:
        raise SpecError(path, "/".join(map(str, exc.path)) or "-",
                        f"invalid schema: {exc.message}") from None
    _VALIDATORS[text] = _Validator(schema)
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


# The keywords of a value's type and range: their message is followed by the description
# of the schema that sets them, which says the quantity and why its range is what it is.
_RANGE_KEYWORDS = {"type", "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum"}


def schema_errors(validator, data, file, report, entry_of=_entry_name):
    """Report every schema error as ``file: entry: where: message`` (the entry named by
    entry_of(data, path)); returns their number."""
    n = 0
    for err in sorted(validator.iter_errors(data), key=lambda e: [str(p) for p in e.path]):
        entry, where = entry_of(data, list(err.path))
        message = err.message
        described = err.schema.get("description") if isinstance(err.schema, dict) else None
        if err.validator in _RANGE_KEYWORDS and described:
            message += f" ({described})"
        report.error(file, entry, f"{where}: {message}" if where else message)
        n += 1
    return n


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
    return schema_errors(validator, data, file, report, _schema_entry)


def check_data_files(spec_dir, files, schema_name, report, check, load=spec_mod.load_yaml):
    """The one loop over the data files of spec/: load each file, check it against
    spec/schemas/<schema_name>, and call check(file, data) for every schema-valid file.
    Nothing stops at the first finding."""
    if not files:
        return
    try:
        validator = load_schema(spec_dir, schema_name)
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


LISTED = 20  # the items a finding lists at most (a long list is cut, with its length)


def listing(items, limit=LISTED):
    """Items joined with ", ", at most `limit` of them and then the count of all: a finding
    that names what would have been right stays one line of bounded length, however many
    findings of its kind a file has."""
    items = list(items)
    text = ", ".join(map(str, items[:limit]))
    return text + (f", ... ({len(items)} in all)" if len(items) > limit else "")


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
        entries = data.get("assumptions")
        for e in entries if isinstance(entries, list) else []:
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
    paths = {key: out_dir / path_of(key) for key in sorted(outputs)}
    write_all({paths[key]: spec_mod.render_json(obj) for key, obj in sorted(outputs.items())})
    for key, path in paths.items():
        print(f"{command}: {describe(key, outputs[key], path)}")
    return 0


def raise_first(report):
    """Raise the report's first error as SpecError, with the count of the others."""
    if report.errors:
        first, more = report.errors[0], len(report.errors) - 1
        raise SpecError(first.file, first.entry,
                        first.reason + (f" (and {more} more)" if more else ""))
