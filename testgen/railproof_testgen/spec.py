"""Loading of spec/ data and writing of the generated JSON. Validation beyond loading lives
in validate.py.

Both loaders (YAML and JSON) reject what a schema cannot see: duplicate keys, and numbers
that are not finite (YAML ``.nan``/``.inf``, JSON ``NaN``/``Infinity`` or a literal too
large for a double such as ``1e400``): a JSON schema's ``minimum``/``maximum`` let NaN
through, since every comparison with NaN is false."""
from __future__ import annotations

import json
import math
from pathlib import Path

import yaml

from .errors import SpecError


class _UniqueKeyLoader(yaml.SafeLoader):
    """SafeLoader that rejects duplicate mapping keys instead of silently overwriting."""


def _construct_mapping(loader, node, deep=False):
    seen = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise yaml.constructor.ConstructorError(
                None, None, f"duplicate key {key!r}", key_node.start_mark)
        seen.add(key)
    return yaml.SafeLoader.construct_mapping(loader, node, deep=deep)


_UniqueKeyLoader.add_constructor(
    yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)


def load_yaml(path: Path):
    path = Path(path)
    try:
        with path.open(encoding="utf-8") as fh:
            data = yaml.load(fh, Loader=_UniqueKeyLoader)  # noqa: S506 (safe loader subclass)
    except FileNotFoundError:
        raise SpecError(path, "-", "file not found") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}" if mark else "-"
        raise SpecError(path, where, f"malformed YAML: {getattr(exc, 'problem', exc)}") from None
    return _checked_document(path, data)


def _reject_constant(token):
    raise ValueError(f"{token} is not a number of JSON")


def _finite_float(text):
    v = float(text)
    if not math.isfinite(v):
        raise ValueError(f"number {text} is out of range")
    return v


def _unique_pairs(pairs):
    out = {}
    for k, v in pairs:
        if k in out:
            raise ValueError(f"duplicate key {k!r}")
        out[k] = v
    return out


def load_json(path: Path):
    """A hand-written JSON data file of spec/ (scenarios, wheel-rail scenarios): an object,
    no duplicate keys, no NaN, Infinity or numbers beyond the range of a double."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SpecError(path, "-", "file not found") from None
    try:
        data = json.loads(text, object_pairs_hook=_unique_pairs, parse_constant=_reject_constant,
                          parse_float=_finite_float)
    except json.JSONDecodeError as exc:
        raise SpecError(path, f"line {exc.lineno}", f"malformed JSON: {exc.msg}") from None
    except ValueError as exc:  # raised by a hook: the decoder gives no position
        raise SpecError(path, "-", f"malformed JSON: {exc}") from None
    return _checked_document(path, data)


def _checked_document(path, data):
    if not isinstance(data, dict):
        raise SpecError(path, "-", "top level must be a mapping")
    where = _non_finite(data, "")
    if where is not None:
        raise SpecError(path, where or "-", "not a finite number")
    return data


def _non_finite(obj, where):
    """Path of the first float that is not finite inside obj, or None."""
    if isinstance(obj, float) and not math.isfinite(obj):
        return where
    items = obj.items() if isinstance(obj, dict) else enumerate(obj) if isinstance(obj, list) else ()
    for k, v in items:
        sub = _non_finite(v, f"{where}[{k}]" if isinstance(k, int) else f"{where}.{k}" if where else str(k))
        if sub is not None:
            return sub
    return None


def render_json(obj):
    """Deterministic JSON text of a generated file (sorted keys, fixed indentation)."""
    return json.dumps(obj, sort_keys=True, indent=1, ensure_ascii=False) + "\n"


def jsonl_records(lines, malformed):
    """(line number, object) of every non-blank line of a JSON Lines text; a malformed line is
    handed to malformed(line number, json.JSONDecodeError) and skipped."""
    for n, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            obj = json.loads(line)
        except json.JSONDecodeError as exc:
            malformed(n, exc)
            continue
        yield n, obj


def spec_files(spec_dir: Path, sub: str):
    return sorted((Path(spec_dir) / sub).glob("*.yaml"))


def load_parameters(spec_dir: Path):
    """Return {area: {"file": path, "parameters": {id: entry}, "model_bounds": {id: entry}}}."""
    out = {}
    for f in spec_files(spec_dir, "parameters"):
        data = load_yaml(f)
        area = data.get("area")
        if not area:
            raise SpecError(f, "area", "missing")
        params, bounds = {}, {}
        for section, target in (("parameters", params), ("model_bounds", bounds)):
            for i, entry in enumerate(data.get(section) or []):
                if not isinstance(entry, dict) or "id" not in entry or "value" not in entry:
                    raise SpecError(f, f"{section}[{i}]", "entry needs 'id' and 'value'")
                pid = entry["id"]
                if pid in params or pid in bounds:
                    raise SpecError(f, pid, "duplicate parameter id")
                v = entry["value"]
                if isinstance(v, bool) or not isinstance(v, (int, float)):
                    raise SpecError(f, pid, f"value must be a number, got {v!r}")
                target[pid] = entry
        out[area] = {"file": f, "parameters": params, "model_bounds": bounds}
    return out
