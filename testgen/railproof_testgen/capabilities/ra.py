"""The re-adhesion part of vector generation: the state machine of models/ra.pml
(spec/design/ra.md §5: detection, parallel start points, re-adhesion judgement, maximum
compensation time, margin in force, sensor failure, stop demand); the engine is vectors.py.

Three files, each with a header that records its configuration. ra.jsonl: two parallel start
points, the model's default configuration; ra.one_start.jsonl: one start point, the model's
variant ONE_START. Every goal of the default configuration is also searched in
ONE_START, and each one reached there adds a vector to the one-start file (coverage entry
"variant_vectors"). Random walks of MODEL_CYCLES cycles (configuration WALK). ra.unit.jsonl:
random walks of MODEL_UNIT_CYCLES cycles in UNIT, the on-board unit's environment at its real
times (models/ra.pml, the MODEL_UNIT_* bounds), replayed through the unit's sensor interface.

Units: model ticks are cycles and the model's margins are fed to the C++ as mm unchanged
(header "units"): the machine only compares ages with t_max and takes minima and maxima of
the limits, so the abstract values are exact.
"""
from __future__ import annotations

import re
from pathlib import Path

from ..errors import PipelineError
from ..vectors import Configuration, Part, model_bounds, model_lines

# ra::Mode and ra::StopReason in order, named as their ToString
MODES = ["TG", "COMPENSATING", "STOPPED"]
REASONS = ["NONE", "MAX_COMPENSATION_TIME", "IMU_FAILURE", "TG_FAILURE", "START_UP", "START_IN_MOTION"]
# the model's section kinds in order (S_LONG, S_STEEP, S_SHORT)
SECTIONS = ["NORMAL", "STEEP", "TIGHT"]
NO_CANDIDATE = 255
UNITS = "model ticks = cycles, model margin units = mm"
BOUNDS = ("confirm", "start_age", "search_extra", "spacing", "tmax_long", "tmax_short", "margin_long",
          "margin_steep", "margin_short", "warmup", "cycles")
# start points of the machine in each configuration
START_POINTS = {None: 2, "ONE_START": 1, "UNIT": 2}
# in UNIT the model redefines a bound by its unit counterpart: #define MODEL_<NAME> MODEL_UNIT_<NAME>
_UNIT_BOUND = re.compile(r"^#define MODEL_(\w+) MODEL_UNIT_\1\s*$", re.M)


def unit_bounds(model) -> tuple:
    """The bounds the model's UNIT configuration takes from MODEL_UNIT_<NAME> (lower case)."""
    return tuple(n.lower() for n in _UNIT_BOUND.findall(Path(model).read_text(encoding="utf-8")))


def configured_bounds(b: dict, define) -> dict:
    """The model bounds in force in a configuration (b holds the unit ones as unit_<name>)."""
    if define != "UNIT":
        return b
    return {**b, **{k[len("unit_"):]: v for k, v in b.items() if k.startswith("unit_")}}

_RX_IN = re.compile(r"@IN cycle dev=([01]) sa0=([01]) sa1=([01]) imu=([01]) tg=([01]) bal=([01]) mv=([01]) "
                    r"sec=(\d+) age=(\d+)")
_RX_OUT = re.compile(r"@OUT mode=(\d+) reason=(\d+) dcount=(\d+) a0=([01]) t0=(\d+) c0=(\d+) "
                     r"a1=([01]) t1=(\d+) c1=(\d+) tmax=(\d+) margin=(\d+) stop=([01]) valid=([01]) "
                     r"det=([01]) adopted=(\d+) breset=([01]) trust=([01]) rest=(\d+)")
_OUT_KEYS = ("mode", "reason", "dcount", "a0", "t0", "c0", "a1", "t1", "c1", "tmax", "margin", "stop",
             "valid", "det", "adopted", "breset", "trust", "rest")


def section_limits(b: dict):
    """Section kind -> (T_s cycles, M_s mm), from the model bounds."""
    return [(b["tmax_long"], b["margin_long"]), (b["tmax_long"], b["margin_steep"]),
            (b["tmax_short"], b["margin_short"])]


class ReAdhesion(Part):
    prefix = "RA"
    configurations = (Configuration(None, walks=1),
                      Configuration("ONE_START", suffix=".one_start", tag="ONESTART-", walks=5),
                      Configuration("UNIT", suffix=".unit", tag="UNIT-", walks=1))
    walk_events = "cycles"

    def bounds(self, model, params_pml):
        unit = unit_bounds(model)
        if not unit:
            raise PipelineError(f"{model}: no MODEL_UNIT_<NAME> redefinition for the configuration UNIT")
        b = model_bounds(params_pml, BOUNDS + tuple(f"unit_{k}" for k in unit))
        # only the bounds the model redefines are the UNIT configuration's
        return {k: v for k, v in b.items() if not k.startswith("unit_") or k[len("unit_"):] in unit}

    def walk_length(self, bounds, define):
        return configured_bounds(bounds, define)["cycles"]

    def parse_events(self, text):
        """Replay/simulation output -> list of (inputs, outputs) per cycle, raw model integers.
        A cycle is complete with its @OUT line; a cycle cut off by the end of a trail or walk is
        dropped."""
        events, pending = [], None
        for kind, m, line in model_lines(text, {"in": _RX_IN, "out": _RX_OUT}):
            if kind == "in":
                pending = {"dev": m[1] == "1", "sa": [m[2] == "1", m[3] == "1"], "imu": m[4] == "1",
                           "tg": m[5] == "1", "bal": m[6] == "1", "mv": m[7] == "1", "sec": int(m[8]),
                           "age": int(m[9])}
            elif pending is None:
                raise PipelineError(f"@OUT without its @IN cycle: {line.strip()}")
            else:
                events.append((pending, {k: int(v) for k, v in zip(_OUT_KEYS, m.groups())}))
                pending = None
        return events

    def to_steps(self, events, b, define):
        """Raw cycles -> vector steps (spec/schemas/vectors_ra.schema.json)."""
        limits = section_limits(configured_bounds(b, define))
        steps = []
        for i, o in events:
            if i["sec"] >= len(SECTIONS) or o["mode"] >= len(MODES) or o["reason"] >= len(REASONS):
                raise PipelineError(f"model output outside the known sections, modes or reasons: {i} {o}")
            if o["adopted"] not in (0, 1, NO_CANDIDATE):
                raise PipelineError(f"unknown adopted candidate {o['adopted']} in the model output")
            t_s, m_s = limits[i["sec"]]
            steps.append({
                "in": {"deviation": i["dev"], "speed_agrees": list(i["sa"]), "imu_ok": i["imu"], "tg_ok": i["tg"],
                       "balise": i["bal"], "tg_moving": i["mv"],
                       "section": {"kind": SECTIONS[i["sec"]], "max_compensation_cycles": t_s, "margin_mm": m_s},
                       "start_age_cycles": i["age"]},
                "out": {"mode": MODES[o["mode"]], "stop_reason": REASONS[o["reason"]],
                        "deviation_count": o["dcount"],
                        "candidates": [{"active": bool(o[f"a{c}"]), "age_cycles": o[f"t{c}"], "confirm": o[f"c{c}"]}
                                       for c in (0, 1)],
                        "max_compensation_cycles": o["tmax"], "margin_mm": o["margin"],
                        "stop_demand": bool(o["stop"]), "position_valid": bool(o["valid"]),
                        "trusted": bool(o["trust"]), "rest_cycles": o["rest"],
                        "detected": bool(o["det"]),
                        "adopted": None if o["adopted"] == NO_CANDIDATE else o["adopted"],
                        "balise_reset": bool(o["breset"])}})
        return steps

    def observed_requirements(self, steps):
        """Requirements evidenced by what a run shows (added to the goal's own). Every step
        compares the margin and maximum compensation time in force (REQ-RA-009)."""
        reqs = {"REQ-RA-009"} if steps else set()
        for s in steps:
            i, o = s["in"], s["out"]
            if o["detected"]:
                reqs.add("REQ-RA-003")
                if o["candidates"][0]["active"]:
                    reqs.add("REQ-RA-004")
                if sum(c["active"] for c in o["candidates"]) == 2:
                    reqs.add("REQ-RA-010")
            if o["adopted"] is not None:
                reqs.update(["REQ-RA-006", "REQ-RA-010"])
            if o["stop_reason"] == "MAX_COMPENSATION_TIME":
                reqs.add("REQ-RA-007")
            if o["stop_reason"] in ("IMU_FAILURE", "TG_FAILURE") and (not i["imu_ok"] or not i["tg_ok"]):
                reqs.add("REQ-RA-013")
            if o["balise_reset"]:
                reqs.add("REQ-RA-012")
            if o["stop_reason"] in ("START_UP", "START_IN_MOTION"):
                reqs.add("REQ-RA-015")
        return reqs

    def header(self, target, define):
        b = configured_bounds(target.bounds, define)
        limits = section_limits(b)
        return target.header(
            configuration=self.configuration(define).name, units=UNITS,
            unit_scales={"cycles_per_tick": 1, "mm_per_margin_unit": 1},
            parameters={
                # ra::MachineConfig of the replay
                "confirm_cycles": b["confirm"], "start_points": START_POINTS[define], "spacing_cycles": b["spacing"],
                "warmup_cycles": b["warmup"],
                # the environment of the model (documentation of the vectors' range)
                "start_age_cycles": [b["start_age"], b["start_age"] + b["search_extra"]],
                "sections": [{"kind": k, "max_compensation_cycles": t, "margin_mm": m}
                             for k, (t, m) in zip(SECTIONS, limits)],
                "model_cycles": b["cycles"],
                "modes": MODES, "stop_reasons": REASONS})


PART = ReAdhesion()
