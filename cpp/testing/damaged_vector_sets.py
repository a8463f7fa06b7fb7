"""Small vector sets made from a capability's real vectors, whole and damaged, for the
conformance runners' rejection tests (cmake/RailproofModules.cmake railproof_conformance,
ctest conformance_<cap>_rejects_<case>):

    python damaged_vector_sets.py --vectors DIR --prefix CAP --out OUT

reads DIR/<CAP>.jsonl (a set the build generated), keeps its header and its two shortest
vector lines as they are (the header sealed again for them: vectors.seal) and writes
OUT/<case>/<CAP>.jsonl for each case below. Only "whole" is a set a runner may accept.
"""
from __future__ import annotations

import argparse
import json
import shutil
import sys
from pathlib import Path

from railproof_testgen.vectors import dump_line, seal


def _first_leaf(obj):
    """(container, key) of the first scalar in obj, depth first."""
    items = obj.items() if isinstance(obj, dict) else enumerate(obj)
    for k, v in items:
        if isinstance(v, (dict, list)):
            if v and (found := _first_leaf(v)):
                return found
        else:
            return obj, k
    return None


def _changed(value):
    if isinstance(value, bool):
        return not value
    if isinstance(value, int):
        return value + 1
    if isinstance(value, str):
        return value + "X"
    return 0


def _sealed(header: dict, lines: list) -> str:
    body = "".join(lines)
    return dump_line(seal(header, body)) + body


def cases(text: str) -> dict:
    """{case: file text} of the whole set in text (a header line, then vector lines)."""
    head, body = text.split("\n", 1)
    header = json.loads(head)
    lines = sorted(body.splitlines(keepends=True), key=len)[:2]
    whole = _sealed(header, lines)
    vector = json.loads(lines[0])
    step = vector["steps"][0]

    changed = json.loads(lines[-1])
    where, key = _first_leaf(changed["steps"][0].get("out") or changed["steps"][0])
    where[key] = _changed(where[key])
    unknown_step = json.loads(lines[0])
    (unknown_step["steps"][0]["in"] if "in" in step else unknown_step["steps"][0])["unknown_input"] = 1
    out_key = next(iter(step["out"])) if "out" in step else next(iter(step))
    target = '"out":{' if "out" in step else '"steps":[{'
    duplicated = lines[0].replace(target, f'{target}"{out_key}":null,', 1)
    return {
        "whole": whole,
        "truncated": "".join(whole.splitlines(keepends=True)[:-1]),
        "changed_vector": whole.split("\n", 1)[0] + "\n" + lines[0] + dump_line(changed),
        "schema_version": _sealed({**header, "schema_version": header["schema_version"] - 1}, lines),
        "unknown_header_key": _sealed({**header, "unknown_field": 1}, lines),
        "unknown_step_key": _sealed(header, [dump_line(unknown_step), lines[1]]),
        "duplicate_key": _sealed(header, [duplicated, lines[1]]),
        "empty_file": "",
        "bad_header": "{not json\n" + "".join(lines),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--vectors", required=True, type=Path)
    ap.add_argument("--prefix", required=True)
    ap.add_argument("--out", required=True, type=Path)
    a = ap.parse_args(argv)
    source = a.vectors / f"{a.prefix}.jsonl"
    try:
        text = source.read_text(encoding="utf-8")
        made = cases(text)
    except (OSError, ValueError, KeyError, IndexError) as exc:
        print(f"damaged_vector_sets: {source}: cannot make the sets ({exc})", file=sys.stderr)
        return 1
    shutil.rmtree(a.out, ignore_errors=True)
    for case, content in made.items():
        (a.out / case).mkdir(parents=True)
        (a.out / case / f"{a.prefix}.jsonl").write_text(content, encoding="utf-8")
    print(f"damaged_vector_sets: {len(made)} sets of {source.name} in {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
