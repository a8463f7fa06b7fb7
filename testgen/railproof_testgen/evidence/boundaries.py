"""Module boundaries (results/layout.json, written by ``railproof_testgen layout``): every
C++ target the build registers with its kind and link closure, as evidence that runtime
code links no offline or test code and that train-side and ground-side code meet only in
the common parts and the messages module. A violation the check found fails the package.
"""
from __future__ import annotations

SIDES = ("common", "onboard", "wayside")


def _kind(kind: str) -> tuple:
    parts = kind.split(":") + ["", ""]
    return parts[0], parts[1], parts[2]


def collect(ctx) -> None:
    layout = ctx.inp.layout
    ctx.layout = None
    if layout is None:
        return
    for v in layout["violations"]:
        ctx.problem(f"module boundaries (layout.json): {v}")
    targets = layout["targets"]
    kinds = {name: _kind(t["kind"]) for name, t in targets.items()}
    runtime, offline, tests = [], [], []
    for name in sorted(targets):
        t = targets[name]
        cls, side, cap = kinds[name]
        closure = t["closure"]
        inner = [d for d in closure if d in targets]
        row = {"name": name, "kind": t["kind"], "capability": cap, "side": side,
               "links": sorted(t["links"]), "closure": sorted(closure),
               "external": sorted(d for d in closure if d not in targets),
               "offline": sorted(d for d in inner if kinds[d][0] == "offline"),
               "test": sorted(d for d in inner if kinds[d][0] == "test"),
               "sides": sorted({kinds[d][1] for d in inner if kinds[d][0] == "runtime"})}
        {"runtime": runtime, "offline": offline}.get(cls, tests).append(row)
    runtime.sort(key=lambda r: (r["capability"], SIDES.index(r["side"]) if r["side"] in SIDES else 9,
                                r["name"]))
    ctx.layout = {"runtime": runtime, "offline": offline, "tests": tests,
                  "violations": list(layout["violations"]),
                  "by_side": {s: [r["name"] for r in runtime if r["side"] == s] for s in SIDES}}
