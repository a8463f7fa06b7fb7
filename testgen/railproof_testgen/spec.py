"""Loading of spec/ data. Validation beyond loading lives in validate.py."""
from __future__ import annotations

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
    if not isinstance(data, dict):
        raise SpecError(path, "-", "top level must be a mapping")
    return data


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
