"""The moving-block part of vector generation (models/mb.pml, spec/design/mb.md §6); the
engine is vectors.py. Each goal is searched in the configuration its annotation names (the
full model is too large for breadth-first search beyond a few cycles) and its vector goes to
that configuration's file, whose header describes it; random walks of 3000 SPIN statements
in the full configuration (mb.jsonl) and in the TRIO and FAIR verification configurations.
The model's units and ticks are turned into mm and ms (design note §2), so the vectors drive
the C++ ground and on-board units directly.
"""
from __future__ import annotations

import re

from ..errors import PipelineError
from ..vectors import Configuration, Part, model_bounds, model_lines

NOTEL = -9
KINDS = ["NONE", "PRECEDING_TRAIN", "FIXED_BLOCK", "ROUTE_END", "HANDOVER", "SYSTEM_BOUNDARY",
         "POSSESSION", "ABNORMAL_TRAIN", "END_OF_TRACK"]
VERDICTS = ["ACCEPT", "TOO_OLD", "NOT_NEWER"]
COMMANDS = {1: "POSSESSION_REQUEST", 2: "POSSESSION_CANCEL", 3: "SIDING_REQUEST", 4: "SIDING_FREE",
            5: "SECURE", 6: "BOUNDARY_ACCEPT"}
POSSESSION = ["NONE", "REQUESTED", "ACTIVE"]
# requirement evidenced by observing an output in a run
KIND_REQS = {"PRECEDING_TRAIN": ["REQ-MB-006"], "FIXED_BLOCK": ["REQ-MB-006"],
             "ROUTE_END": ["REQ-MB-006", "REQ-MB-013"], "HANDOVER": ["REQ-MB-006", "REQ-MB-017"],
             "SYSTEM_BOUNDARY": ["REQ-MB-006", "REQ-MB-023"], "POSSESSION": ["REQ-MB-006", "REQ-MB-014"],
             "ABNORMAL_TRAIN": ["REQ-MB-006", "REQ-MB-004"], "END_OF_TRACK": ["REQ-MB-006", "REQ-MB-023"]}

_RX = {
    "env_in": re.compile(r"@IN env cmd=(\d+) arg=(\d+)"),
    "env_out": re.compile(r"@OUT env poss=(\d+) side_req=(\d+)"),
    "rep_in": re.compile(r"@IN report t=(\d+) front=(\d+) ext=(\d+)"),
    "rep_out": re.compile(r"@OUT report t=(\d+) tracked=(\d+)"),
    "tick_in": re.compile(r"@IN tick"),
    "train_out": re.compile(r"@OUT train t=(\d+) grant=(-?\d+) why=(\d+) abn=(\d+) usable=(\d+)"),
    "il_out": re.compile(r"@OUT il main=(\d+) side=(\d+) pts=(\d+) poss=(\d+) occ=(\d+)"),
    "dl_in": re.compile(r"@IN deliver t=(\d+) lim=(-?\d+) age=(\d+)"),
    "dl_out": re.compile(r"@OUT ob t=(\d+) verdict=(\d+) lim=(-?\d+)"),
}


def _expect(pending, ev, line):
    if pending is None or pending["ev"] != ev:
        raise PipelineError(f"@OUT without its @IN {ev}: {line.strip()}")


class Scale:
    """Model units and ticks -> mm and ms (design note §2)."""

    def __init__(self, b):
        self.b = b
        self.S = b["unit_mm"]
        self.T = b["tick_ms"]

    def front(self, f):
        return (f + 1) * self.S

    def limit(self, lim):
        return None if lim == NOTEL else (lim + 1) * self.S

    def section(self, lo, hi):
        return [lo * self.S, (hi + 1) * self.S]


def _ext(b, p):
    e = (p % b["balise_spacing_units"]) // b["odo_units_per_ext"]
    return min(e, b["ext_max"])


class MovingBlock(Part):
    prefix = "MB"
    configurations = (
        Configuration(None, walks=1),
        Configuration("CORE", suffix=".core"),
        Configuration("TRIO", suffix=".trio", tag="TRIO", walks=8),
        Configuration("FEATURE_POSS", suffix=".feature_poss"),
        Configuration("FEATURE_ROUTE", suffix=".feature_route"),
        Configuration("FEATURE_RADIO", suffix=".feature_radio"),
        Configuration("FAIR", suffix=".fair", tag="FAIR", walks=8, walk_evidence=True),
    )
    boundary_words = ("boundary", "edge")
    walk_defines = ()
    walk_steps = 3000

    def bounds(self, model, params_pml):
        return model_bounds(params_pml)

    def parse_events(self, text):
        """Replay/simulation output -> list of raw (input, output) events; a tick's output is
        complete only with its `@OUT il` line (an input cut off by the end of a trail is dropped)."""
        events, pending, trains = [], None, []
        for kind, m, line in model_lines(text, _RX):
            if kind == "env_in":
                pending = {"ev": "cmd", "cmd": int(m[1]), "arg": int(m[2])}
            elif kind == "rep_in":
                pending = {"ev": "report", "t": int(m[1]), "front": int(m[2]), "ext": int(m[3])}
            elif kind == "tick_in":
                pending, trains = {"ev": "tick"}, []
            elif kind == "dl_in":
                pending = {"ev": "deliver", "t": int(m[1]), "lim": int(m[2]), "age": int(m[3])}
            elif kind == "env_out":
                _expect(pending, "cmd", line)
                events.append((pending, {"poss": int(m[1]), "side_req": int(m[2])}))
                pending = None
            elif kind == "rep_out":
                _expect(pending, "report", line)
                events.append((pending, {"tracked": int(m[2])}))
                pending = None
            elif kind == "train_out":
                _expect(pending, "tick", line)
                trains.append({"t": int(m[1]), "grant": int(m[2]), "why": int(m[3]), "abn": int(m[4]),
                               "usable": int(m[5])})
            elif kind == "il_out":
                _expect(pending, "tick", line)
                events.append((pending, {"trains": trains, "main": int(m[1]), "side": int(m[2]),
                                         "pts": int(m[3]), "poss": int(m[4]), "occ": int(m[5])}))
                pending, trains = None, []
            else:
                _expect(pending, "deliver", line)
                events.append((pending, {"verdict": int(m[2]), "lim": int(m[3])}))
                pending = None
        return events

    def to_steps(self, events, b, define):
        sc = Scale(b)
        steps = []
        accepted = set()  # trains whose on-board unit holds an accepted authority
        for i, o in events:
            ev = i["ev"]
            if ev == "cmd":
                cmd = COMMANDS[i["cmd"]]
                steps.append({"in": {"ev": "cmd", "cmd": cmd, "train": i["arg"] if cmd == "SECURE" else None},
                              "out": {"possession": POSSESSION[o["poss"]], "siding_requested": bool(o["side_req"])}})
            elif ev == "report":
                steps.append({"in": {"ev": "report", "train": i["t"], "front_mm": sc.front(i["front"]),
                                     "correction_mm": i["ext"] * sc.S},
                              "out": {"tracked": bool(o["tracked"])}})
            elif ev == "tick":
                trains = [{"limit_mm": sc.limit(t["grant"]) if t["abn"] else (t["grant"] + 1) * sc.S,
                           "kind": KINDS[t["why"]], "abnormal": bool(t["abn"]),
                           "authority_usable": bool(t["usable"])}
                          for t in sorted(o["trains"], key=lambda x: x["t"])]
                occupied = [b for b in range(sc.b["blocks"]) if o["occ"] >> b & 1]
                steps.append({"in": {"ev": "tick"},
                              "out": {"trains": trains, "main_route": bool(o["main"]), "siding_route": bool(o["side"]),
                                      "points_reverse": bool(o["pts"]), "possession": POSSESSION[o["poss"]],
                                      "occupied": occupied}})
            else:
                verdict = VERDICTS[o["verdict"]]
                if verdict == "ACCEPT":
                    accepted.add(i["t"])
                steps.append({"in": {"ev": "deliver", "train": i["t"], "limit_mm": (i["lim"] + 1) * sc.S,
                                     "age_ms": i["age"] * sc.T},
                              "out": {"verdict": verdict,
                                      "limit_mm": (o["lim"] + 1) * sc.S if i["t"] in accepted else None}})
        return steps

    def observed_requirements(self, steps):
        reqs = set()
        for s in steps:
            ev, out = s["in"]["ev"], s["out"]
            if ev == "report":
                reqs.update(["REQ-MB-001", "REQ-MB-003"])
            elif ev == "deliver":
                reqs.add("REQ-MB-009")
            elif ev == "cmd":
                cmd = s["in"]["cmd"]
                reqs.add({"POSSESSION_REQUEST": "REQ-MB-014", "POSSESSION_CANCEL": "REQ-MB-014",
                          "SIDING_REQUEST": "REQ-MB-012", "SIDING_FREE": "REQ-MB-012",
                          "SECURE": "REQ-MB-017", "BOUNDARY_ACCEPT": "REQ-MB-023"}[cmd])
            else:
                reqs.update(["REQ-MB-010", "REQ-MB-024"])
                for t in out["trains"]:
                    reqs.update(KIND_REQS.get(t["kind"], []))
                    if t["abnormal"]:
                        reqs.add("REQ-MB-004")
        return reqs

    def header(self, target, config):
        b = target.bounds
        sc = Scale(b)
        S = sc.S
        nt = {"CORE": 2, "FEATURE_POSS": 2, "FEATURE_ROUTE": 2, "FEATURE_RADIO": 2}.get(config, b["trains"])
        preset = config in ("CORE", "FAIR", "FEATURE_POSS", "FEATURE_ROUTE")
        return target.header(
            configuration=self.configuration(config).name,
            unit_scales={"time_ms_per_tick": sc.T, "mm_per_unit": S},
            parameters={
                "line_mm": b["line_units"] * S,
                "blocks_mm": [k * b["block_units"] * S for k in range(b["blocks"] + 1)],
                "platform_mm": sc.section(b["platform_first_unit"], b["platform_last_unit"]),
                "points_mm": sc.section(b["points_first_unit"], b["points_last_unit"]),
                "route_main_mm": sc.section(b["points_first_unit"], b["route_last_unit"]),
                "possession_mm": sc.section(b["possession_first_unit"], b["possession_last_unit"]),
                "handover_mm": b["handover_unit"] * S, "boundary_mm": b["boundary_unit"] * S,
                "margins_mm": {k: b[f"margin_{k}"] * S for k in
                               ("train", "fixed_block", "route", "handover", "boundary", "possession",
                                "abnormal", "eot")},
                "train_length_mm": b["train_units"] * S,
                "initial_front_mm": [sc.front(b[f"init_front_{k}"]) for k in range(nt)],
                "initial_correction_mm": [_ext(b, b[f"init_front_{k}"]) * S for k in range(nt)],
                "tracking_timeout_ms": b["track_timeout_ticks"] * sc.T,
                "validity_ms": b["link_ticks"] * sc.T, "max_age_ms": b["max_age_ticks"] * sc.T,
                "secured_at_start": preset or config == "FEATURE_POSS",
                "boundary_accepted_at_start": preset,
            })

    def order(self, define, vectors):
        """The main file by kind and id, the configurations' files as generated (goal order,
        then the walks by seed)."""
        return sorted(vectors, key=lambda v: (v["kind"] == "random", v["id"])) if define is None else vectors


PART = MovingBlock()
