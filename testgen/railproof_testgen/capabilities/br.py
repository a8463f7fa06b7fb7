"""The braking part of vector generation: the supervision decision of models/br.pml
(spec/design/br.md §4: brake-level selection, emergency-brake latch and release); the engine
is vectors.py. Goals whose label names a boundary give the boundary vectors (v_s exactly at
and one above a pattern speed); random walks of MODEL_CYCLES cycles (configuration WALK), in
the model's default configuration (br.jsonl) and in REALISABLE, the on-board unit's
environment (br.unit.jsonl).

Units: the model's speeds are abstract integers 0..MODEL_VMAX; the vectors carry them
unchanged and the conformance harness feeds them to br::Supervisor as mm/s. This is exact
because the decision only compares the supervised speed with the pattern speeds (header
"units"). Two files, br.jsonl and br.unit.jsonl (schema spec/schemas/vectors_br.schema.json).
"""
from __future__ import annotations

import re

from ..errors import PipelineError
from ..vectors import Configuration, Part, model_bounds, model_lines

# br::BrakeLevel in order, named as br::ToString
LEVELS = ["NONE", "4N", "5N", "6N", "7N", "EB"]
# the model's pattern speeds p0..p5 in the order of br::PatternSpeeds
PATTERNS = ["v_e", "v_7n", "v_6n", "v_5n", "v_4n", "v_release"]
UNITS = "abstract speed units = mm/s"
# requirement evidenced by observing an output level in a run
LEVEL_REQS = {"NONE": ["REQ-BR-003"], "4N": ["REQ-BR-003"], "5N": ["REQ-BR-003"], "6N": ["REQ-BR-003"],
              "7N": ["REQ-BR-002"], "EB": ["REQ-BR-001", "REQ-BR-006"]}

_RX = {
    "cycle": re.compile(r"@IN cycle vs=(\d+) st=([01]) he=([01]) rs=([01])"),
    "pick": re.compile(r"@IN p(\d)=(\d+)"),
    "out": re.compile(r"@OUT level=(\d) appr=([01]) latched=([01])"),
}



class Braking(Part):
    prefix = "BR"
    # REALISABLE: the on-board unit's environment (models/br.pml); its walks are br.unit.jsonl,
    # the vectors the unit-level replay drives through the on-board unit
    configurations = (Configuration(None, walks=1),
                      Configuration("REALISABLE", suffix=".unit", tag="UNIT-", walks=1))
    walk_events = "cycles"

    def bounds(self, model, params_pml):
        return model_bounds(params_pml, ("vmax", "cycles"))

    def parse_events(self, text):
        """Replay/simulation output -> list of (inputs, outputs) per cycle. A cycle is complete
        with its @OUT line; a cycle cut off by the end of a trail or walk is dropped."""
        events, pending = [], None
        for kind, m, line in model_lines(text, _RX):
            if kind == "cycle":
                pending = {"v_s": int(m[1]), "standstill": m[2] == "1", "handle_emergency": m[3] == "1",
                           "reset": m[4] == "1"}
            elif kind == "pick":
                k = int(m[1])
                if pending is None or k >= len(PATTERNS) or PATTERNS[k] in pending:
                    raise PipelineError(f"pattern speed outside a cycle or repeated: {line.strip()}")
                pending[PATTERNS[k]] = int(m[2])
            else:
                if pending is None or any(p not in pending for p in PATTERNS):
                    raise PipelineError(f"@OUT without a complete @IN cycle: {line.strip()}")
                events.append((pending, {"level": int(m[1]), "appr": m[2] == "1", "latched": m[3] == "1"}))
                pending = None
        return events

    def to_steps(self, events, bounds, define):
        """Raw cycles -> vector steps (spec/schemas/vectors_br.schema.json)."""
        steps = []
        for i, o in events:
            if o["level"] >= len(LEVELS):
                raise PipelineError(f"unknown brake level {o['level']} in the model output")
            steps.append({"in": {"v_s": i["v_s"], **{p: i[p] for p in PATTERNS},
                                 "standstill": i["standstill"], "handle_emergency": i["handle_emergency"],
                                 "reset": i["reset"]},
                          "out": {"level": LEVELS[o["level"]], "pattern_approaching": o["appr"],
                                  "emergency_latched": o["latched"]}})
        return steps

    def observed_requirements(self, steps):
        reqs = set()
        for s in steps:
            reqs.update(LEVEL_REQS[s["out"]["level"]])
            if s["out"]["pattern_approaching"]:
                reqs.add("REQ-BR-003")
        return reqs

    def header(self, target, define):
        b = target.bounds
        return target.header(configuration=self.configuration(define).name, units=UNITS, unit_scales={"speed_mm_s_per_unit": 1},
                             parameters={"model_vmax": b["vmax"], "model_cycles": b["cycles"], "levels": LEVELS})


PART = Braking()
