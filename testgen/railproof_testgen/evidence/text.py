"""Text for reStructuredText pages and sphinx-needs: need ids, escaping, numbers.

Everything the templates show passes through one of these functions (they are also the
Jinja filters ``rst``, ``line`` and ``num``), so no input text can end a line, open a
markup construct or be read by sphinx-needs as a dynamic function.
"""
from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

_NEED_ID_BAD = re.compile(r"[^A-Za-z0-9_-]+")
_RST_SPECIAL = re.compile(r"([\\`*_|])")
_RST_BLOCK_START = re.compile(r"^(?:[-+•]\s|\d+[.)]\s|[a-zA-Z#][.)]\s|\.\.(?:\s|$)|::|>>>)")
_PLAIN = re.compile(r"[!-~](?:[ -~]*[!-~])?")
_NOT_PLAIN = re.compile(r"  |\[\[|\]\]|<<|>>")


def need_id(*parts: str, upper: bool = True) -> str:
    """A sphinx-needs id from free text: [A-Za-z0-9_-] only (upper case unless upper=False),
    starting with a letter; matches needs_id_regex in evidence/conf.py."""
    text = "_".join(p for p in parts if p)
    nid = _NEED_ID_BAD.sub("_", text.upper() if upper else text).strip("_")
    if not nid or not nid[0].isalpha():
        nid = "X_" + nid
    return nid.ljust(3, "_")     # needs_id_regex: at least three characters


def no_dynamic(text: str) -> str:
    """sphinx-needs reads ``[[...]]`` in a need's fields and content as a dynamic function
    call; adjacent brackets are spaced apart so input text is never executed."""
    text = re.sub(r"\[(?=\[)", "[ ", text)
    return re.sub(r"\](?=\])", "] ", text)


def rst_escape(value) -> str:
    """Escape inline reStructuredText markup characters; newlines become spaces; a leading
    list, enumeration or comment marker and a trailing ``::`` are escaped so a table cell
    stays one paragraph; ``[[``/``]]`` are spaced apart (see no_dynamic)."""
    text = _RST_SPECIAL.sub(r"\\\1", " ".join(str(value).split()))
    if _RST_BLOCK_START.match(text):
        text = "\\" + text
    if text.endswith("::"):       # a paragraph ending in "::" announces a literal block
        text = text[:-1] + "\\:"
    return no_dynamic(text)


def one_line(value) -> str:
    """Directive arguments and option values: one line, no leading/trailing blanks, no
    ``[[``/``]]`` (see no_dynamic)."""
    return no_dynamic(" ".join(str(value).split()))


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
    return no_dynamic("".join(out)) or "(empty)"


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


def flatten(obj: dict, prefix: str = "") -> dict:
    """{"a": {"b": 1}, "c": [1, 2]} -> {"a.b": 1, "c": [1, 2]} (lists kept as values)."""
    out: dict = {}
    for k, v in obj.items():
        key = f"{prefix}.{k}" if prefix else str(k)
        if isinstance(v, dict) and v:
            out.update(flatten(v, key))
        else:
            out[key] = v
    return out


def fields(obj: dict, skip=()) -> list:
    """[(key, formatted value)] of the entries of obj not in skip, sorted by key: the
    extra fields of a result entry that the page shows beside its known ones."""
    return sorted((str(k), fmt_value(v)) for k, v in obj.items() if k not in skip)


def safe_json_line(obj) -> str:
    """One JSON line for display inside need content. sphinx-needs treats ``[[`` ... ``]]``
    in need content as a dynamic function, so adjacent brackets are spaced apart (the
    verbatim file is linked beside it)."""
    return no_dynamic(json.dumps(obj, sort_keys=True, ensure_ascii=False))


def sha256_file(path: Path) -> str:
    h = hashlib.sha256()
    with Path(path).open("rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()
