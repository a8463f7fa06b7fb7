"""Module boundaries of the C++ tree (conventions §2, spec/design/layout.md).

``railproof_testgen layout --repo . --targets build/gen/targets.json [--out layout.json]``

The build records every target it registers (cmake/RailproofModules.cmake) with its kind
and its direct links in build/gen/targets.json:

  runtime:<side>:<cap>   a runtime module (side common, onboard or wayside)
  offline                an offline module or tool
  test:<what>:<cap>      test-only code (test executables, the seeded-fault variants)

Rules, each violation printed as ``file-or-target: entry: reason`` (exit 1 if any):
1. the link closure of a runtime module holds only runtime modules and the external
   libraries of RUNTIME_EXTERNAL (no offline module, no test code, no Ipopt/OMPL/Box2D/JSON);
2. train side and ground side never meet except through common parts and the messages
   module: the closure of an onboard module holds no wayside module and vice versa, and a
   common module links neither side;
3. a runtime unit-test executable (test:runtime) links no offline module;
4. a file under cpp/runtime includes no offline or test header (railproof/offline/,
   railproof/sim/, railproof/<cap>/analysis/, railproof/testing/), and a file of one side
   includes no header of the other side (railproof/<cap>/wayside/ from an onboard file, ...).
   The compiler enforces the rest: a module sees only the headers of what it links.
"""
from __future__ import annotations

import json
import re
import sys
from pathlib import Path

from . import add_command
from .errors import PipelineError
from .files import write_json

RUNTIME_EXTERNAL = {"PkgConfig::SODIUM"}
SIDES = ("common", "onboard", "wayside")
_INCLUDE = re.compile(r'^[ \t]*#[ \t]*include[ \t]+"(railproof/[^"]+)"', re.M)
_FORBIDDEN_IN_RUNTIME = re.compile(r"^railproof/(offline|sim|testing)/|^railproof/[a-z]{2}/analysis/")


def _kind(entry: str):
    parts = entry.split(":")
    return parts[0], (parts[1] if len(parts) > 1 else ""), (parts[2] if len(parts) > 2 else "")


def load_targets(path: Path) -> dict:
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise PipelineError(f"{path}: no target list (configure the build first)") from None
    except json.JSONDecodeError as exc:
        raise PipelineError(f"{path}: malformed target list: {exc}") from None
    return data["targets"]


def closure(targets: dict, name: str) -> set:
    seen, todo = set(), list(targets.get(name, {}).get("links", []))
    while todo:
        t = todo.pop()
        if t in seen:
            continue
        seen.add(t)
        todo.extend(targets.get(t, {}).get("links", []))
    return seen


def side_of_file(rel: str):
    """(capability, side) of a file under cpp/runtime/<cap>/, side None outside a side folder."""
    parts = Path(rel).parts
    if len(parts) < 3 or parts[:2] != ("cpp", "runtime"):
        return None, None
    cap = parts[2]
    for s in ("onboard", "wayside", "common"):
        if s in parts[3:]:
            return cap, s
    return cap, None


def check(repo: Path, targets: dict) -> tuple:
    errors, report = [], {}
    for name, t in sorted(targets.items()):
        kind, side, cap = _kind(t["kind"])
        clo = closure(targets, name)
        report[name] = {"kind": t["kind"], "links": t["links"], "closure": sorted(clo)}
        if kind == "runtime":
            for d in sorted(clo):
                if d in targets:
                    dk, dside, _ = _kind(targets[d]["kind"])
                    if dk != "runtime":
                        errors.append(f"{name}: {d}: a runtime module links {dk} code")
                    elif side in ("onboard", "wayside") and dside not in ("common", side):
                        errors.append(f"{name}: {d}: {side} code links {dside} code (they meet only in "
                                      f"railproof_messages)")
                    elif side == "common" and dside in ("onboard", "wayside"):
                        errors.append(f"{name}: {d}: a common part links {dside} code")
                elif d not in RUNTIME_EXTERNAL:
                    errors.append(f"{name}: {d}: a runtime module links an external library outside "
                                  f"{sorted(RUNTIME_EXTERNAL)}")
        if kind == "test" and side == "runtime":
            for d in sorted(clo):
                if d in targets and _kind(targets[d]["kind"])[0] == "offline":
                    errors.append(f"{name}: {d}: a runtime test links offline code")
    repo = Path(repo)
    for f in sorted((repo / "cpp" / "runtime").rglob("*")):
        if f.suffix not in (".cpp", ".hpp") or not f.is_file():
            continue
        rel = str(f.relative_to(repo))
        if "/tests/" in rel or "/conformance/" in rel or "/bench/" in rel or "/fuzz/" in rel:
            continue  # test code of the module, not the module
        cap, side = side_of_file(rel)
        text = f.read_text(encoding="utf-8")
        for m in _INCLUDE.finditer(text):
            inc = m.group(1)
            line = text.count("\n", 0, m.start()) + 1
            if _FORBIDDEN_IN_RUNTIME.search(inc):
                errors.append(f"{rel}: line {line}: runtime code includes {inc} (offline or test code)")
            for other in ("onboard", "wayside"):
                if re.match(rf"^railproof/[a-z]{{2}}/{other}/", inc) and side not in (other, None):
                    errors.append(f"{rel}: line {line}: {side} code includes {inc}")
                if re.match(rf"^railproof/[a-z]{{2}}/{other}/", inc) and side is None and cap not in ("units",):
                    errors.append(f"{rel}: line {line}: common code includes {inc}")
    return errors, report


def run(args) -> int:
    targets = load_targets(Path(args.targets))
    errors, report = check(Path(args.repo), targets)
    for e in errors:
        print(e, file=sys.stderr)
    if args.out:
        write_json(Path(args.out), {"schema": "railproof/layout/1", "violations": errors,
                                    "targets": report}, if_changed=False)
    if errors:
        print(f"layout: {len(errors)} boundary violation(s)", file=sys.stderr)
        return 1
    runtime = sum(1 for t in targets.values() if t["kind"].startswith("runtime"))
    print(f"layout: {len(targets)} targets ({runtime} runtime), no boundary violation")
    return 0


def register(sub):
    add_command(sub, "layout", run,
                "check the module boundaries of the C++ tree (runtime/offline, train/ground, includes)",
                repo="repository root", targets="build/gen/targets.json",
                out={"help": "write the target graph and the findings here (JSON)"})
