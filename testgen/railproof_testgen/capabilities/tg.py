"""The radio telegram layer's part of vector generation (models/tg.pml, spec/design/tg.md §7,
schema spec/schemas/vectors_tg.schema.json); the engine is vectors.py.

Each run of the model is emitted once per endpoint role (ground, train): the logic is the same,
the identifiers, telegram types and safe-reaction output differ, so a vector id ends in the
role. Trap vectors come from the default configuration; a goal it cannot reach is searched
again in the boundary variant VARIANT_NARROW_WINDOW, whose vectors go to
tg.variant_narrow_window.jsonl with the variant's window in the header. Random walks of
--walk-steps SPIN statements (about 60 per event) in the default configuration and, as
evidence of the property verified there, on the healthy channel (HEALTHY).
"""
from __future__ import annotations

import re

from ..errors import PipelineError, SpecError
from ..vectors import Configuration, Part, model_bounds

VERDICTS = ["ACCEPT", "REJ_INTEGRITY", "REJ_ADDRESS", "REJ_AUTH", "REJ_REPEATED", "REJ_SEQUENCE",
            "REJ_NO_ECHO", "REJ_UNKNOWN_ECHO", "REJ_STALE"]
LINKS = ["NONE", "UP", "LOST"]
NONE = 255
# delivery modes of the model (D_INTACT ... D_MISADDR)
MODE_INTACT, MODE_DUP, MODE_CORRUPT, MODE_FORGE, MODE_MISADDR = range(5)
ROLES = ("ground", "train")

# requirement evidenced by observing a verdict / transition in a run
VERDICT_REQS = {
    "ACCEPT": ["REQ-TG-008"], "REJ_INTEGRITY": ["REQ-TG-005"], "REJ_ADDRESS": ["REQ-TG-003"],
    "REJ_AUTH": ["REQ-TG-007"], "REJ_REPEATED": ["REQ-TG-001"], "REJ_SEQUENCE": ["REQ-TG-004"],
    "REJ_NO_ECHO": ["REQ-TG-012"], "REJ_UNKNOWN_ECHO": ["REQ-TG-008"],
    "REJ_STALE": ["REQ-TG-006", "REQ-TG-009"],
}
LOST_REQS = ["REQ-TG-013", "REQ-TG-014", "REQ-TG-015"]
IDENTIFIERS = ("ground_id", "train_id", "other_train_id")

_IN_TICK = re.compile(r"@IN tick")
_IN_RX = re.compile(r"@IN rx seq=(\d+) echo=(\d+) mode=(\d+)")
# an output line: its name, the input it answers, its fields in order
_OUTPUTS = ((re.compile(r"@OUT tx seq=(\d+) echo=(\d+) link=(\d+) eb=(\d+) abnormal=(\d+)"), "tx", "tick",
             ("seq", "echo", "link", "eb", "abnormal")),
            (re.compile(r"@OUT rx verdict=(\d+) gap=(\d+) link=(\d+) eb=(\d+) abnormal=(\d+)"), "rx", "rx",
             ("verdict", "gap", "link", "eb", "abnormal")))


def _role_out(role, o):
    base = {"link": LINKS[o["link"]]}
    if role == "train":
        base["eb"] = bool(o["eb"])
    else:
        base["tracking"] = "ABNORMAL" if o["abnormal"] else "TRACKED"
    return base


class Telegram(Part):
    prefix = "TG"
    configurations = (
        Configuration(None, walks=1),
        Configuration("VARIANT_NARROW_WINDOW", suffix=".variant_narrow_window"),
        Configuration("HEALTHY", tag="HEALTHY", walks=10, walk_evidence=True),
    )
    boundary_words = ("boundary", "edge", "wrap")
    variant_search = "unreachable"
    walk_defines = ()
    walk_steps = 7000

    def bounds(self, model, params_pml):
        return model_bounds(params_pml, ("tick_ms", "seq_modulus", "seq_window", "history_depth",
                                         "turnaround_ticks", "link_ticks", "echo_ticks", "init_own_seq",
                                         "init_peer_seq", *IDENTIFIERS))

    def parse_events(self, text):
        """Replay/simulation output -> list of raw (input, output) events; an input whose
        output was cut off by the end of a trail is dropped."""
        events, pending = [], None
        for line in text.splitlines():
            if _IN_TICK.search(line):
                pending = {"ev": "tick"}
            elif m := _IN_RX.search(line):
                pending = {"ev": "rx", "seq": int(m[1]), "echo": int(m[2]), "mode": int(m[3])}
            else:
                for rx, name, ev, fields in _OUTPUTS:
                    if m := rx.search(line):
                        if pending is None or pending["ev"] != ev:
                            raise PipelineError(f"@OUT {name} without @IN {ev}: {line.strip()}")
                        events.append((pending, {f: int(v) for f, v in zip(fields, m.groups())}))
                        pending = None
                        break
        return events

    def to_steps(self, events, bounds, define, role="ground"):
        """Raw events -> the vector steps of one endpoint role."""
        steps = []
        own, peer, other = (bounds[k] for k in IDENTIFIERS)
        for i, o in events:
            if i["ev"] == "tick":
                out = {"tx": {"seq": o["seq"], "echo": None if o["echo"] == NONE else o["echo"]}}
                out.update(_role_out(role, o))
                steps.append({"in": {"ev": "tick"}, "out": out})
                continue
            mode = i["mode"]
            if role == "ground":
                src, dst, typ = peer, own, "POSITION"
                if mode == MODE_MISADDR:
                    src = other
            else:
                src, dst, typ = own, peer, "CONTROL"
                if mode == MODE_MISADDR:
                    dst = other
            tg = {"src": src, "dst": dst, "type": typ, "seq": i["seq"],
                  "echo": None if i["echo"] == NONE else i["echo"],
                  "auth": "nokey" if mode == MODE_FORGE else "key",
                  "integrity": "corrupt" if mode == MODE_CORRUPT else "ok"}
            out = {"verdict": VERDICTS[o["verdict"]], "gap": o["gap"]}
            out.update(_role_out(role, o))
            steps.append({"in": {"ev": "rx", "tg": tg}, "out": out})
        return steps

    def observed_requirements(self, events):
        """Requirements a run shows, from the raw events (the same for both roles)."""
        reqs = set()
        prev_link = 0
        for i, o in events:
            if i["ev"] == "rx":
                reqs.update(VERDICT_REQS[VERDICTS[o["verdict"]]])
            if prev_link == 1 and o["link"] == 2:
                reqs.update(LOST_REQS)
            prev_link = o["link"]
        return reqs

    def vectors(self, target, define, events, vid, kind, goal, seed, requirements):
        """One run, one vector per endpoint role."""
        reqs = sorted(set(requirements) | self.observed_requirements(events))
        return [{"id": f"{vid}-{role}", "role": role, "requirements": reqs, "goal": goal, "kind": kind,
                 "seed": seed, "steps": self.to_steps(events, target.bounds, define, role)} for role in ROLES]

    def vector_id(self, kind, define, tail):
        """A variant's goal vectors carry the variant after the goal: TG-BOUNDARY-G12narrowwindow."""
        if define and define.startswith("VARIANT_"):
            return f"TG-{kind.upper()}-{tail}{define.lower()[len('variant_'):].replace('_', '')}"
        return super().vector_id(kind, define, tail)

    def order(self, define, vectors):
        """As generated: goal vectors in goal order, then the walks by configuration and seed."""
        return vectors

    def header(self, target, define):
        b = target.bounds
        params = {"seq_modulus": b["seq_modulus"], "seq_window": b["seq_window"],
                  "history_depth": b["history_depth"],
                  "turnaround_ms": b["turnaround_ticks"] * b["tick_ms"],
                  "link_timeout_ms": b["link_ticks"] * b["tick_ms"],
                  "echo_validity_ms": b["echo_ticks"] * b["tick_ms"],
                  "init_own_seq": b["init_own_seq"], "init_peer_seq": b["init_peer_seq"],
                  **{k: b[k] for k in IDENTIFIERS}}
        extra = {}
        variant = next((v for v in target.annotations.variants if v.define == define), None)
        if variant is not None:  # the variant's file: its parameter overridden
            if variant.bound not in b:
                raise SpecError(target.path, define, f"variant names unknown model bound {variant.bound}")
            params[variant.parameter] = b[variant.bound]
            extra["variant"] = define
        return target.header(unit_scales={"time_ms_per_tick": b["tick_ms"]}, parameters=params, **extra)


PART = Telegram()
