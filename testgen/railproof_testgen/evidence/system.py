"""The system page: the train and the ground as two units (cpp/runtime/units,
spec/design/units.md) and the system simulator that drives them (cpp/offline/sim,
spec/design/sim.md).

Gathers what the page shows from the generic results, never re-reading a file:
- the units' test set (``unit_units``: the unit tests, the two-unit handover and the
  capabilities' vectors replayed through the units' external interfaces) and the
  replay cases among them;
- the seeded faults of the units' glue (registry section ``units``) with their killers;
- every simulator scenario summary (``railproof/sim-summary/``) as one row, and the
  invariants checked in it: per invariant (requirement or assumption) and scenario the
  checks and the violations.
The scenarios' own tables, the D5 gap sweep and the D2 headway study stay in their
chapters (mb, fc); the page links to them.
"""
from __future__ import annotations

from .text import fmt_value

SUMMARY_SCHEMA = "railproof/sim-summary/"
UNITS_SET = "unit_units"
REPLAY_MARKERS = ("Replay", "Vectors")
DESIGN_NOTES = ("spec/design/units.md", "spec/design/sim.md")


def _replay_cases(group: dict) -> list:
    rows = []
    for f in group["files"]:
        for s in f["suites"]:
            if not any(m in s["name"] for m in REPLAY_MARKERS):
                continue
            for c in s["cases"]:
                rows.append({"suite": s["name"], "name": c.get("title") or c.get("name", ""),
                             "result": c.get("result", ""), "id": c.get("id", "")})
    return rows


def collect(ctx) -> None:
    sets = [g for g in ctx.test_groups if g["key"] == UNITS_SET]
    # the registry's units section promises the units (and their glue faults): then their tests must run
    promised = any(o["name"] == "units" and o["faults"] for o in ctx.inp.fault_owners)
    if promised and not sets:
        ctx.problem("the units' test set (ctest entries units.*, results/tests/unit/units/) did not run")
    scenarios = [a for a in ctx.analyses if a["schema"].startswith(SUMMARY_SCHEMA)]
    invariants: list = []
    for a in scenarios:
        for key in (a["data"].get("checks") or {}):
            if key not in invariants:
                invariants.append(key)
    invariants.sort()
    rows, matrix = [], []
    for a in scenarios:
        d = a["data"]
        rows.append([str(d.get("scenario") or a["stem"]), str(d.get("line") or ""),
                     str(len(d["trains"]) if isinstance(d.get("trains"), list) else 0),
                     fmt_value(d.get("simulated_s")), fmt_value(d.get("violations")),
                     str(d.get("result") or "n/a")])
    for inv in invariants:
        cells = []
        for a in scenarios:
            c = (a["data"].get("checks") or {}).get(inv)
            cells.append("–" if not isinstance(c, dict) else
                         f"{fmt_value(c.get('checks'))} / {fmt_value(c.get('violations'))}")
        matrix.append([inv] + cells)
    ctx.system = {
        "sets": sets,
        "replay": [r for g in sets for r in _replay_cases(g)],
        "faults": [f for f in ctx.faults if f["capability"] == "units"],
        "scenario_rows": rows,
        "scenario_names": [r[0] for r in rows],
        "invariants": matrix,
        "design_notes": [n for n in DESIGN_NOTES if any(f.rel == n for f in ctx.inp.files)],
        "chapters": [ch["name"] for ch in ctx.chapters],
    }
