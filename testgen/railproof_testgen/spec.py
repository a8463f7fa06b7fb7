"""Loading of spec/ data and writing of the generated JSON. Validation beyond loading lives
in validate.py.

Every data file is read within fixed limits, checked before the text is expanded into
Python values, so that no input makes a load take unbounded time or memory, and every
refusal is one ``file: entry: reason`` (SpecError), never a traceback
(spec/design/data.md §1.1):

- the file: a regular file (not a directory, device or pipe) of at most
  ``MAX_FILE_BYTES``, UTF-8 text;
- the document: at most ``MAX_DEPTH`` nested collections (the YAML composer and the JSON
  decoder recurse per level), at most ``MAX_NODES`` values with every YAML alias expanded
  (the alias bomb: a few lines of anchors standing for billions of values), at most
  ``MAX_ALIASES`` aliases and none that refers to its own anchor, strings (and keys) of at
  most ``MAX_STRING`` characters, integers of at most 64 bits' worth of digits;
- the values: JSON's alone (mapping with string keys, list, string, number, boolean, null):
  YAML's dates, sets, binary and pairs are refused, as are duplicate keys and numbers that
  are not finite (YAML ``.nan``/``.inf``, JSON ``NaN``/``Infinity`` or a literal too large
  for a double such as ``1e400``): a JSON schema's ``minimum``/``maximum`` let NaN through,
  since every comparison with NaN is false."""
from __future__ import annotations

import json
import math
import re
import stat
from pathlib import Path

import yaml

from .errors import SpecError

# The limits of a loaded file. The largest file of spec/ is about 18 KB, 2 000 lines and 7
# levels deep (the JSON schemas 13), with strings of at most 1 400 characters and no
# aliases; each limit leaves one to two orders of magnitude above that and bounds the work
# of every later step (schema, checks, conversion), which is linear in the number of values.
MAX_FILE_BYTES = 1 << 20
MAX_DEPTH = 32
MAX_NODES = 200_000
MAX_ALIASES = 100
MAX_STRING = 16_384
MAX_INT_DIGITS = 40  # a 64-bit integer has at most 20 decimal digits (64 binary ones)


def read_text(path: Path) -> str:
    """The UTF-8 text of the regular file path, of at most MAX_FILE_BYTES (SpecError if not);
    the size is checked before the file is read, and the read stops at the limit (a file that
    grows, or a special file reporting no size, cannot pass it)."""
    path = Path(path)
    try:
        st = path.stat()
    except FileNotFoundError:
        raise SpecError(path, "-", "file not found") from None
    except OSError as exc:
        raise SpecError(path, "-", f"cannot read: {exc.strerror or exc}") from None
    if stat.S_ISDIR(st.st_mode):
        raise SpecError(path, "-", "is a directory, not a file")
    if not stat.S_ISREG(st.st_mode):
        raise SpecError(path, "-", "not a regular file")
    too_big = f"file larger than the limit of {MAX_FILE_BYTES} bytes"
    if st.st_size > MAX_FILE_BYTES:
        raise SpecError(path, "-", f"{too_big} ({st.st_size} bytes)")
    try:
        with path.open("rb") as fh:
            data = fh.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise SpecError(path, "-", f"cannot read: {exc.strerror or exc}") from None
    if len(data) > MAX_FILE_BYTES:
        raise SpecError(path, "-", too_big)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise SpecError(path, f"line {line}", f"not UTF-8 text (byte 0x{data[exc.start]:02x} "
                                              f"at offset {exc.start})") from None


class _LimitError(yaml.YAMLError):
    """A limit of the loader exceeded at a place of the YAML text."""

    def __init__(self, mark, reason):
        super().__init__(reason)
        self.problem_mark, self.problem = mark, reason


try:  # libyaml scans and parses in C, iteratively: about ten times faster than PyYAML's own
    from yaml.cyaml import CParser as _Events
except ImportError:  # pragma: no cover - PyYAML built without libyaml
    class _Events(yaml.reader.Reader, yaml.scanner.Scanner, yaml.parser.Parser):
        def __init__(self, stream):
            yaml.reader.Reader.__init__(self, stream)
            yaml.scanner.Scanner.__init__(self)
            yaml.parser.Parser.__init__(self)


class _Loader(yaml.composer.Composer, _Events, yaml.constructor.SafeConstructor,
              yaml.resolver.Resolver):
    """PyYAML's safe loading (SafeLoader's constructor and resolver, on the events of
    libyaml's parser where PyYAML has it) within the limits above: duplicate mapping keys
    are refused instead of silently overwritten, the nesting depth, alias count and string
    length are checked as the document is composed (before anything recurses deeper or is
    copied), integers of more digits than 64 bits need before they are converted."""

    def __init__(self, stream):
        _Events.__init__(self, stream)
        yaml.composer.Composer.__init__(self)
        yaml.constructor.SafeConstructor.__init__(self)
        yaml.resolver.Resolver.__init__(self)
        self._depth = 0
        self._aliases = 0
        self._nodes = 0

    def compose_node(self, parent, index):
        event = self.peek_event()
        self._nodes += 1
        if self._nodes > MAX_NODES:
            raise _LimitError(event.start_mark, f"more than {MAX_NODES} values")
        if isinstance(event, yaml.AliasEvent):
            self._aliases += 1
            if self._aliases > MAX_ALIASES:
                raise _LimitError(event.start_mark, f"more than {MAX_ALIASES} aliases")
            return super().compose_node(parent, index)
        if isinstance(event, yaml.ScalarEvent):
            if len(event.value) > MAX_STRING:
                raise _LimitError(event.start_mark, f"a value of {len(event.value)} characters "
                                                    f"exceeds the limit of {MAX_STRING}")
            return super().compose_node(parent, index)
        if self._depth >= MAX_DEPTH:
            raise _LimitError(event.start_mark, f"nested deeper than {MAX_DEPTH} levels")
        self._depth += 1
        try:
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def construct_yaml_int(self, node):
        if len(node.value) > MAX_INT_DIGITS:
            raise _LimitError(node.start_mark, f"an integer of {len(node.value)} digits is beyond "
                                               "64 bits")
        return super().construct_yaml_int(node)

    def construct_object(self, node, deep=False):
        """As SafeLoader's, but a scalar its tag cannot read (``!!int abc``, the date
        2024-13-45) is a ConstructorError at its place, not a Python exception."""
        try:
            return super().construct_object(node, deep=deep)
        except (ValueError, KeyError, TypeError, OverflowError):
            if not isinstance(node, yaml.ScalarNode):
                raise
            raise yaml.constructor.ConstructorError(
                None, None, f"{node.value!r} cannot be read as {node.tag.rsplit(':', 1)[-1]}",
                node.start_mark) from None

    def refuse_non_json(self, node):
        """YAML's own types (dates, sets, binary, ordered pairs) have no JSON form."""
        what = node.tag.rsplit(":", 1)[-1]
        raise yaml.constructor.ConstructorError(
            None, None, f"a {what} is not a value of JSON (write it in quotes if it is text)",
            node.start_mark)


def _construct_mapping(loader, node, deep=False):
    seen = set()
    for key_node, _ in node.value:
        if key_node.tag == "tag:yaml.org,2002:merge":
            raise yaml.constructor.ConstructorError(
                None, None, "merge keys (<<) are not read: write the keys out",
                key_node.start_mark)
        if not isinstance(key_node, yaml.ScalarNode):
            raise yaml.constructor.ConstructorError(
                None, None, "a key must be a string, not a "
                + ("mapping" if isinstance(key_node, yaml.MappingNode) else "list"),
                key_node.start_mark)
        key = loader.construct_object(key_node, deep=deep)
        if not isinstance(key, str):
            raise yaml.constructor.ConstructorError(
                None, None, f"key {key_node.value!r} is not a string (write it in quotes)",
                key_node.start_mark)
        if key in seen:
            raise yaml.constructor.ConstructorError(
                None, None, f"duplicate key {key!r}", key_node.start_mark)
        seen.add(key)
    return yaml.constructor.SafeConstructor.construct_mapping(loader, node, deep=deep)


_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)
_Loader.add_constructor("tag:yaml.org,2002:int", _Loader.construct_yaml_int)
for _tag in ("timestamp", "set", "binary", "omap", "pairs"):
    _Loader.add_constructor(f"tag:yaml.org,2002:{_tag}", _Loader.refuse_non_json)


def _expanded_size(root):
    """The number of nodes of the composed YAML document with every alias expanded (a node
    reached twice counts twice), computed once per node, without expanding anything; a
    _LimitError at an alias that refers to a node containing it (a cyclic document)."""
    size, active = {}, set()
    stack = [(root, False)]
    while stack:
        node, done = stack.pop()
        key = id(node)
        if done:
            active.discard(key)
            children = _children(node)
            size[key] = 1 + sum(size[id(c)] for c in children)
            if size[key] > MAX_NODES:
                raise _LimitError(node.start_mark, f"more than {MAX_NODES} values (aliases "
                                                   "expanded)")
            continue
        if key in size:
            continue
        if key in active:
            raise _LimitError(node.start_mark, "an alias refers to a value that contains it")
        active.add(key)
        stack.append((node, True))
        for c in _children(node):
            if id(c) in active:
                raise _LimitError(c.start_mark, "an alias refers to a value that contains it")
            if id(c) not in size:
                stack.append((c, False))
    return size[id(root)]


def _children(node):
    if isinstance(node, yaml.MappingNode):
        return [n for pair in node.value for n in pair]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


def load_yaml(path: Path):
    """A YAML file of spec/ within the limits above: a mapping of JSON values."""
    path = Path(path)
    text = read_text(path)
    loader = _Loader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            raise SpecError(path, "-", "top level must be a mapping")
        if loader._aliases:
            _expanded_size(node)
        data = loader.construct_document(node)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}" if mark else "-"
        problem = getattr(exc, "problem", None) or exc
        kind = "YAML beyond the loader's limits" if isinstance(exc, _LimitError) \
            else "malformed YAML"
        raise SpecError(path, where, f"{kind}: {problem}") from None
    finally:
        loader.dispose()
    return _checked_document(path, data)


def _reject_constant(token):
    raise ValueError(f"{token} is not a number of JSON")


def _finite_float(text):
    v = float(text)
    if not math.isfinite(v):
        raise ValueError(f"number {text} is out of range")
    return v


def _bounded_int(text):
    if len(text) > MAX_INT_DIGITS:
        raise ValueError(f"an integer of {len(text)} digits is beyond 64 bits")
    return int(text)


def _unique_pairs(pairs):
    out = {}
    for k, v in pairs:
        if k in out:
            raise ValueError(f"duplicate key {k!r}")
        out[k] = v
    return out


_JSON_STRING = re.compile(r'"(?:[^"\\]|\\.)*"', re.S)
_JSON_BRACKET = re.compile(r"[\[\]{}]")


def _json_depth_line(text):
    """The line at which the JSON text nests deeper than MAX_DEPTH, or None; checked on the
    text before it is decoded (the decoder recurses per level). Strings are skipped, so a
    bracket inside a string does not count."""
    depth = 0
    for m in _JSON_BRACKET.finditer(_JSON_STRING.sub(lambda s: " " * len(s.group()), text)):
        if m.group() in "[{":
            depth += 1
            if depth > MAX_DEPTH:
                return text.count("\n", 0, m.start()) + 1
        else:
            depth -= 1
    return None


def parse_json(path, text):
    """The JSON text of path decoded within the limits above (SpecError if not): no
    duplicate keys, no NaN, Infinity or numbers beyond the range of a double."""
    line = _json_depth_line(text)
    if line is not None:
        raise SpecError(path, f"line {line}", f"JSON beyond the loader's limits: nested deeper "
                                              f"than {MAX_DEPTH} levels")
    try:
        return json.loads(text, object_pairs_hook=_unique_pairs, parse_constant=_reject_constant,
                          parse_float=_finite_float, parse_int=_bounded_int)
    except json.JSONDecodeError as exc:
        raise SpecError(path, f"line {exc.lineno}", f"malformed JSON: {exc.msg}") from None
    except ValueError as exc:  # raised by a hook: the decoder gives no position
        raise SpecError(path, "-", f"malformed JSON: {exc}") from None


def load_json(path: Path):
    """A hand-written JSON data file of spec/ (scenarios, wheel-rail scenarios) within the
    limits above: an object of JSON values."""
    path = Path(path)
    return _checked_document(path, parse_json(path, read_text(path)))


_JSON_SCALARS = (str, int, float, bool, type(None))


def label(section, item, index):
    """Entry name of item `index` of list `section`: ``section[<id or name>]``, else the index."""
    if isinstance(item, dict):
        for key in ("id", "name"):
            v = item.get(key)
            if isinstance(v, (str, int)) and not isinstance(v, bool) and v != "":
                return f"{section}[{v}]"
    return f"{section}[{index}]"


def _checked_document(path, data):
    if not isinstance(data, dict):
        raise SpecError(path, "-", "top level must be a mapping")
    problem = _value_problem(data)
    if problem is not None:
        where, reason = problem
        raise SpecError(path, where or "-", reason)
    return data


def _value_problem(data):
    """(path, reason) of the first value of data (in document order) that is not a finite
    JSON value within the limits (a string too long, more values than MAX_NODES), or None.
    Iterative: nothing here recurses."""
    count = 0
    stack = [(data, "")]
    while stack:
        obj, where = stack.pop()
        count += 1
        if count > MAX_NODES:
            return "", f"more than {MAX_NODES} values"
        if isinstance(obj, float) and not math.isfinite(obj):
            return where, "not a finite number"
        if isinstance(obj, str) and len(obj) > MAX_STRING:
            return where, f"a value of {len(obj)} characters exceeds the limit of {MAX_STRING}"
        if isinstance(obj, dict):
            for k in obj:
                if not isinstance(k, str):
                    return where, f"key {k!r} is not a string"
                if len(k) > MAX_STRING:
                    return where, f"a key of {len(k)} characters exceeds the limit of {MAX_STRING}"
            children = [(v, f"{where}.{k}" if where else k) for k, v in obj.items()]
        elif isinstance(obj, list):
            children = [(v, label(where, v, i)) for i, v in enumerate(obj)]
        elif isinstance(obj, _JSON_SCALARS):
            continue
        else:
            return where, (f"a {type(obj).__name__} is not a value of JSON (write it in "
                           "quotes if it is text)")
        stack.extend(reversed(children))
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
        if not isinstance(area, str):
            raise SpecError(f, "area", "must be a string")
        params, bounds = {}, {}
        for section, target in (("parameters", params), ("model_bounds", bounds)):
            entries = data.get(section) or []
            if not isinstance(entries, list):
                raise SpecError(f, section, "must be a list")
            for i, entry in enumerate(entries):
                if not isinstance(entry, dict) or "id" not in entry or "value" not in entry:
                    raise SpecError(f, f"{section}[{i}]", "entry needs 'id' and 'value'")
                pid = entry["id"]
                if not isinstance(pid, str):
                    raise SpecError(f, f"{section}[{i}]", "id must be a string")
                if pid in params or pid in bounds:
                    raise SpecError(f, pid, "duplicate parameter id")
                v = entry["value"]
                if isinstance(v, bool) or not isinstance(v, (int, float)):
                    raise SpecError(f, pid, f"value must be a number, got {v!r}")
                target[pid] = entry
        out[area] = {"file": f, "parameters": params, "model_bounds": bounds}
    return out
