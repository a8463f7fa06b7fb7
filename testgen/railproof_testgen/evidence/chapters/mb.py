"""The moving-block chapter's own content: the line simulator's scenarios (summaries,
the gap sweep, time-distance plots with their event logs) and the descriptions of the
verification configurations of models/mb.pml (its header comment, spec/design/mb.md §5).
"""
from __future__ import annotations

from collections import Counter

from ..text import fmt_value

RESULT_DIRS = ["scenarios"]
STUDY_FILES = {"scenarios": "analysis/scenario_*.json"}
SUMMARY_SCHEMA = "railproof/sim-summary/"
SWEEP_SCHEMA = "railproof/sim-sweep/"

CONFIGURATIONS = {
    "default": "the full model: every train of the model bounds and every environment command "
               "(possession, siding route, radio cells, boundary) with every fault",
    "CORE": "2 trains over the whole line; every report, tracking, set-back and telegram fault "
            "(loss, delay, re-ordering); no infrastructure commands",
    "TRIO": "3 trains with every fault of CORE, confined to the first blocks: the next radio cell "
            "is never secured, so the handover point ends their run (the platform, the only fixed "
            "block and set-back section, lies before it)",
    "FEATURE_POSS": "2 trains; possessions requested, confirmed and cancelled at any time "
                    "(telegrams lost but not held back)",
    "FEATURE_ROUTE": "2 trains; the siding route over the points requested and freed at any time "
                     "(telegrams lost but not held back)",
    "FEATURE_RADIO": "2 trains; radio cells secured and the boundary accepted at any time "
                     "(telegrams lost but not held back)",
    "FAIR": "a healthy system: every report and telegram arrives in its cycle, no possession or "
            "siding request; for the progress property",
}


def _obj(d: dict, key: str) -> dict:
    return d.get(key) if isinstance(d.get(key), dict) else {}


def _scenario(a: dict, plots: set, logs: dict) -> dict:
    d = a["data"]
    name = str(d.get("scenario") or a["stem"].removeprefix("scenario_"))
    gap = _obj(d, "gap")
    faults = Counter(str(f.get("type", "?")) for f in d.get("faults") or [] if isinstance(f, dict))
    return {"name": name, "analysis": a["id"], "rel": a["rel"],
            "description": str(d.get("description") or ""), "line": str(d.get("line") or ""),
            "running_line": str(d.get("running_line") or ""),
            "simulated_s": fmt_value(d.get("simulated_s")),
            "trains": len(d["trains"]) if isinstance(d.get("trains"), list) else 0,
            "train_km": fmt_value(_obj(d, "progress").get("train_km")),
            "faults": ", ".join(f"{t} {n}" if n > 1 else t for t, n in faults.items()) or "none",
            "violations": fmt_value(d.get("violations")), "result": str(d.get("result") or "n/a"),
            "gap": fmt_value(gap.get("settled_gap_m")) if gap else "n/a",
            "plot": name if name in plots else "", "log": logs.get(name, "")}


def _sweep(a: dict) -> dict:
    d = a["data"]
    rows = []
    for r in d.get("runs") or []:
        if isinstance(r, dict):
            g = _obj(r, "gap")
            rows.append([fmt_value(r.get("leader_cap_kmh")), str(r.get("result", "n/a")),
                         fmt_value(r.get("violations"))]
                        + [fmt_value(g.get(k)) for k in ("leader_speed_kmh", "follower_speed_kmh",
                                                         "settled_gap_m", "min_m", "max_m", "window_s",
                                                         "samples")])
    return {"analysis": a["id"], "rel": a["rel"], "scenario": str(d.get("scenario") or ""),
            "line": str(d.get("line") or ""), "rows": rows,
            "grows": fmt_value(d.get("gap_grows_with_speed")), "result": str(d.get("result") or "n/a")}


def build(ctx, ch: dict) -> None:
    files = ctx.inp.result_dirs.get("scenarios", [])
    logs = {n[:-len(".log.json")]: f"scenarios/{n}" for n, _ in files if n.endswith(".log.json")}
    plots = {p["name"] for p in ch["plots"] if p["dir"] == "scenarios"}
    ch["scenarios"], ch["sweeps"] = [], []
    for a in ch["studies"].get("scenarios", []):
        schema = a["schema"]
        if schema.startswith(SUMMARY_SCHEMA):
            ch["scenarios"].append(_scenario(a, plots, logs))
        elif schema.startswith(SWEEP_SCHEMA):
            ch["sweeps"].append(_sweep(a))
    by_plot = {s["plot"]: s for s in ch["scenarios"] if s["plot"]}
    for p in ch["plots"]:
        p["scenario"] = by_plot.get(p["name"]) if p["dir"] == "scenarios" else None
    ch["plots_without_summary"] = sorted(plots - set(by_plot))
