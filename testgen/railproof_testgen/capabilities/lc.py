"""The level-crossing part of vector generation: models/lc.pml and models/lc_gnss.pml
(spec/design/lc.md §3-§6: the on-board crossing function, the crossing controllers and the
centre scheduler), one part per model (PARTS); the engine is
vectors.py. Each goal is searched in the configuration its annotation names; random walks in
configuration WALK (at most MODEL_CYCLES ticks; GNSS runs end at the model's horizon). One
file per configuration, each with a header that records it:

  lc.jsonl               ONBOARD, one train (the model's default configuration)
  lc.long_warning.jsonl  ONBOARD, design warning time one tick longer
  lc.two_trains.jsonl    ONBOARD, a second train requesting crossing A
  lc_gnss.jsonl          GNSS-time pre-armed crossings (losses, delays, barriers), models/lc_gnss.pml
  lc_gnss.clock.jsonl    GNSS with GNSS outages and clock faults

Units (header "unit_scales"): a model tick is TICK_MS ms, a model cell CELL_MM mm (positions
are half-cells), a speed unit (cells per tick) SPEED_MM_S mm/s, the acceleration 1 cell/tick²
ACCEL_MM_S2 mm/s². Every unit of the C++ runs on the same `now` each tick. The model keeps times
relative (ONBOARD) or in half-ticks (GNSS); the generator turns the run into absolute times:
a warning start is the tick the model reports a new warning, a report's issue time the tick
of the controller cycle that issued it (the model prints each telegram's age on delivery),
a start time (half-ticks + 2W) is converted exactly. The model's ETA class (eta2, half-ticks)
is checked against an exact re-computation of the C++ rounding (EarliestArrivalMs of the
design, one profile piece) for every value that occurs: the tick length is valid only if
floor(E * TICK_MS) keeps the class, which the generator asserts.
"""
from __future__ import annotations

import math
import re
from pathlib import Path

from ..errors import PipelineError, SpecError
from ..spin import model_text
from ..vectors import Configuration, Part, model_bounds, model_lines

TICK_MS = 10_000
CELL_MM = 100_000
HALF_MM = CELL_MM // 2
SPEED_MM_S = CELL_MM * 1000 // TICK_MS          # 1 cell per tick
ACCEL_MM_S2 = CELL_MM * 1_000_000 // TICK_MS ** 2  # 1 cell per tick²
TRAIN_ID = 1
OTHER_TRAIN_ID = 2
CROSSING_IDS = (1, 2)
DEPARTURE_ID = 1
MAX_WARNING_MS = 1_000_000_000_000  # the model has no alarm: never reached in a run
UNITS = "model tick = 10000 ms, model cell = 100000 mm (positions in half-cells)"

# names as the C++ ToString
CONTROLLER_STATES = ["OPEN", "WARNING", "CLOSING", "CLOSED", "OPENING", "FAILED"]
ONBOARD_STATES = ["APPROACHING", "REQUESTED", "CLEARED", "PASSED", "DONE"]
STATUS_OF = {"OPEN": "OPEN", "OPENING": "OPEN", "WARNING": "WARNING", "CLOSING": "WARNING", "CLOSED": "CLOSED",
             "FAILED": "FAILED"}
FAILURE_FROM = {"CLOSING": "BARRIER_NOT_DOWN", "CLOSED": "BARRIER_DOWN_LOST", "OPENING": "BARRIER_NOT_UP"}
CLOCK_INPUTS = ["GNSS", "NO_GNSS", "FAULT"]
CLOCK_STATES = ["SYNCHRONISED", "HOLDOVER", "FAULTY"]

# the model's variant of each configuration and the ticks it adds to the design warning time
VARIANT = {None: ("ONBOARD", 0), "LONG_WARNING": ("ONBOARD", 1), "TWO_TRAINS": ("ONBOARD", 0),
           "GNSS": ("GNSS", 0), "GNSS_CLOCK": ("GNSS", 0)}
# model bounds of spec/parameters/lc.yaml, and the model-local ones (defaults in the
# model, overridden by the parameters file once they are there)
BOUNDS = ("track", "vmax", "lc_a", "lc_b", "train_len", "station", "warn_ticks", "lower_ticks", "max_delay",
          "cycles")
LOCAL = ("lead_ticks", "conf_age_ticks", "prot_offset", "dwell_ticks", "gnss_dwell_ticks", "holdover_ticks",
         "response_ticks", "gnss_horizon", "gnss_faults")

_LOCAL_DEFAULT = re.compile(r"#ifndef MODEL_(\w+)\s*\n#define MODEL_\1 ([^/\n]+?)\s*(?:/\*|\n)")

# ---- the model's output -------------------------------------------------------------------------
_RX = {
    "tick": re.compile(r"@IN tick (?:t=(\d+) )?x=(\d+) v=(\d+) ph=(\d+) dw=(\d+)"),
    "ul": re.compile(r"@IN ul c=([01]) age=([01]) m=([12])"),
    "other": re.compile(r"@IN other ev=([012])"),
    "bar": re.compile(r"@IN bar c=([01]) down=([01]) up=([01])"),
    "ctrl": re.compile(r"@OUT ctrl c=([01]) cs=(\d) wa=(\d+) new=([01]) ack=([01]) rq=([01])"),
    "rx": re.compile(r"@IN rx c=([01]) age=([01])"),
    "board": re.compile(r"@OUT board s0=(\d) s1=(\d) e0=(\d+) e1=(\d+) lim=(\d+)"),
    "move": re.compile(r"@OUT move x=(\d+) v=(\d+)"),
    "pos": re.compile(r"@IN pos age=([01])"),
    "ua": re.compile(r"@IN ua c=([01]) age=([12])"),
    "centre": re.compile(r"@OUT centre clr=([01]) " + " ".join(
        f"st{c}=(\\d+) p{c}=([01]) a{c}=([01]) x{c}=([01]) sp{c}=([01]) sa{c}=([01]) cf{c}=([01])" for c in (0, 1))),
    "ds": re.compile(r"@IN ds c=([01]) age=([01])"),
    "clk": re.compile(r"@IN clk c=([01]) k=([012])"),
    "gctrl": re.compile(r"@OUT gctrl c=([01]) cs=(\d) wa=(\d+) new=([01]) pres=([01]) pst=(\d+) act=([01]) "
                        r"ck=([012]) ack=(\d+) acc=([01]) sack=([01])"),
}


# ---- bounds and the header ---------------------------------------------------------------------
def model_local_defaults(model: Path) -> dict:
    """The model-local bounds (#ifndef MODEL_X / #define MODEL_X n) of the model and the shared
    parts it includes (models/include/lc_shared.pml)."""
    out = {}
    for name, value in _LOCAL_DEFAULT.findall(model_text(model)):
        key = name.lower()
        if key in LOCAL:
            try:
                out[key] = int(value)
            except ValueError:
                pass
    return out


def all_bounds(model: Path, params_pml: Path) -> dict:
    b = model_bounds(params_pml, BOUNDS)
    local = model_local_defaults(model)
    local.setdefault("dwell_ticks", local.get("lead_ticks", 0) + 1)  # the model's default expression
    for key in LOCAL:
        if key not in b and key not in local:
            raise SpecError(model, f"MODEL_{key.upper()}", "model-local bound not found in the model")
        b.setdefault(key, local.get(key))
    return b


def timing(b: dict, config) -> dict:
    """Ticks of the configuration (the model's W, LOWER, TO, ...)."""
    w = b["warn_ticks"] + VARIANT[config][1]
    return {"W": w, "LOWER": b["lower_ticks"], "TO": w - b["lower_ticks"], "LEAD": b["lead_ticks"],
            "CMA": b["conf_age_ticks"], "PO": b["prot_offset"], "DWELL": b["dwell_ticks"],
            "GDWELL": b["gnss_dwell_ticks"], "HOLD": b["holdover_ticks"], "OFS": 2 * w}


def crossings(b: dict, config):
    t = timing(b, config)
    return [{"id": cid, "near_mm": lc * CELL_MM, "far_mm": (lc + 1) * CELL_MM, "warning_time_ms": t["W"] * TICK_MS}
            for cid, lc in zip(CROSSING_IDS, (b["lc_a"], b["lc_b"]))]


# ---- the exact ETA of the C++ (design §2, one profile piece) --------------------------------------
def eta_ms(d_mm: int, v_mm_s: int, a: int, c: int) -> int:
    """EarliestArrivalMs for one piece of limit c (design §2, the C++ formula)."""
    if d_mm <= 0:
        return 0
    c = max(c, v_mm_s)
    if 2 * a * d_mm >= c * c - v_mm_s * v_mm_s:
        return (1000 * ((c - v_mm_s) ** 2 + 2 * a * d_mm)) // (2 * a * c)
    v2 = v_mm_s * v_mm_s + 2 * a * d_mm
    return (math.isqrt(1_000_000 * v2) - 1000 * v_mm_s) // a


def eta_class(ms: int) -> int:
    """The model's eta2 of a C++ ETA in ms: 2 floor(E) + (E not whole), E in ticks."""
    return 2 * (ms // TICK_MS) + (1 if ms % TICK_MS else 0)


def check_eta(x: int, v: int, dwell_ticks: int, near_hc: int, eta2: int, b: dict, where: str):
    ms = eta_ms((near_hc - x) * HALF_MM, v * SPEED_MM_S, ACCEL_MM_S2, b["vmax"] * SPEED_MM_S)
    if near_hc - x > 0:
        ms += dwell_ticks * TICK_MS
    if eta_class(ms) != eta2:
        raise PipelineError(f"{where}: the model's ETA class {eta2} differs from the C++ rounding of "
                            f"{ms} ms (tick length {TICK_MS} ms too coarse for this fraction)")


# ---- conversion to vector steps ------------------------------------------------------------------
def _report(cid, status, ws, issued, requesters, clock_fault=False):
    """A controller report; it lists the controller's requesters (design §3 item 3: a CLOSED
    report clears only a train it lists)."""
    return {"crossing_id": cid, "status": status, "warning_start_ms": ws, "issued_ms": issued,
            "clock_fault": clock_fault, "requesters": requesters}


def _failure(prev_state, state, prev_failure):
    if state == "FAILED" and prev_state != "FAILED":
        return FAILURE_FROM[prev_state]
    return prev_failure if state == "FAILED" else "NONE"


def _controller_state(k, c, o, now, t, state, ws, failure):
    """The state controller c takes in tick k (the model's output o: cs, new, wa); its
    warning start ws[c], failure[c] and state[c] are updated and its warning age checked."""
    new_state = CONTROLLER_STATES[o["cs"]]
    if o["new"]:
        ws[c] = now
    failure[c] = _failure(state[c], new_state, failure[c])
    if new_state in ("WARNING", "CLOSING", "CLOSED") or (new_state == "FAILED" and failure[c] != "BARRIER_NOT_UP"):
        if min((now - ws[c]) // TICK_MS, t["W"]) != o["wa"]:
            raise PipelineError(f"tick {k}: controller {c}: warning age {o['wa']} disagrees with ws {ws[c]}")
    state[c] = new_state
    return new_state


def onboard_steps(ticks, b: dict, config):
    """Raw ONBOARD ticks -> vector steps (controllers' cycles, then the on-board cycle)."""
    t = timing(b, config)
    near = [2 * b["lc_a"], 2 * b["lc_b"]]
    ws = [0, 0]
    state = ["OPEN", "OPEN"]
    failure = ["NONE", "NONE"]
    requesters = [[], []]
    issued = []  # per tick: per crossing the report and whether our withdrawal was acknowledged
    ob_prev = [0, 0]
    steps = []
    for k, tk in enumerate(ticks):
        now = k * TICK_MS
        ctrls, tick_reports = [], []
        for c in (0, 1):
            o = tk["ctrl"].get(c)
            if o is None or c not in tk["bar"]:
                raise PipelineError(f"tick {k}: controller {c} output or barrier input missing")
            reqs = [TRAIN_ID for u in tk["ul"] if u["c"] == c and u["m"] == 1]
            wds = [TRAIN_ID for u in tk["ul"] if u["c"] == c and u["m"] == 2]
            if c == 0 and tk["other"] == 1:
                reqs.append(OTHER_TRAIN_ID)
            if c == 0 and tk["other"] == 2:
                wds.append(OTHER_TRAIN_ID)
            for tr in reqs:
                if tr not in requesters[c]:
                    requesters[c].append(tr)
            for tr in wds:
                if tr in requesters[c]:
                    requesters[c].remove(tr)
            if (TRAIN_ID in requesters[c]) != bool(o["rq"]):
                raise PipelineError(f"tick {k}: controller {c}: requester tracking disagrees with the model")
            new_state = _controller_state(k, c, o, now, t, state, ws, failure)
            status = STATUS_OF[new_state]
            rep = _report(CROSSING_IDS[c], status, ws[c] if status != "OPEN" else 0, now,
                          list(requesters[c]))
            acks = [tr for tr in wds]
            if bool(o["ack"]) != (TRAIN_ID in acks):
                raise PipelineError(f"tick {k}: controller {c}: acknowledgement disagrees with the model")
            tick_reports.append((rep, TRAIN_ID in acks))
            down, up = tk["bar"][c]
            ctrls.append({
                "crossing_id": CROSSING_IDS[c],
                "in": {"requests": reqs, "withdrawals": wds, "barrier_down": bool(down), "barrier_up": bool(up)},
                "out": {"state": new_state, "warning_start_ms": ws[c] if new_state not in ("OPEN",) else None,
                        "report": rep, "withdrawal_acks": acks, "requesters": list(requesters[c]),
                        "lights_on": new_state != "OPEN",
                        "barriers_down_commanded": new_state in ("CLOSING", "CLOSED", "FAILED"),
                        "failure": failure[c]}})
        issued.append(tick_reports)
        # the on-board cycle
        reports, acks = [], []
        for r in tk["rx"]:
            src = k - r["age"]
            if src < 0:
                raise PipelineError(f"tick {k}: a report of tick {src}")
            rep, acked = issued[src][r["c"]]
            reports.append(rep)
            if acked:
                acks.append({"crossing_id": CROSSING_IDS[r["c"]], "train_id": TRAIN_ID})
        bo = tk["board"]
        if bo is None:
            raise PipelineError(f"tick {k}: on-board output missing")
        dwell = tk["ph"] == 1
        etas = []
        for c in (0, 1):
            if ob_prev[c] <= 2:
                dwell_ticks = tk["dw"] if dwell else 0
                check_eta(tk["x"], tk["v"], dwell_ticks, near[c], bo["e"][c], b, f"tick {k} crossing {c}")
                etas.append(bo["e"][c])
            else:
                etas.append(None)
        states = [ONBOARD_STATES[s] for s in bo["s"]]
        steps.append({
            "t_ms": now,
            "controllers": ctrls,
            "train": {"front_mm": tk["x"] * HALF_MM, "speed_mm_s": tk["v"] * SPEED_MM_S, "dwell": dwell,
                      "departure_ms": (k + tk["dw"]) * TICK_MS if dwell else 0},
            "onboard": {"in": {"reports": reports, "acks": acks},
                        "out": {"states": states, "eta_half_ticks": etas,
                                "requests": [CROSSING_IDS[c] for c in (0, 1) if states[c] in ("REQUESTED", "CLEARED")],
                                "withdrawals": [CROSSING_IDS[c] for c in (0, 1) if states[c] == "PASSED"],
                                "stop_limit_mm": None if bo["lim"] == 255 else bo["lim"] * HALF_MM}}})
        ob_prev = bo["s"]
    return steps


def _start_ms(half_ticks_ofs: int, t: dict) -> int:
    return (half_ticks_ofs - t["OFS"]) * TICK_MS // 2


def gnss_steps(ticks, b: dict, config):
    """Raw GNSS ticks -> vector steps (the centre's cycle, then the controllers')."""
    t = timing(b, config)
    ws = [0, 0]
    state = ["OPEN", "OPEN"]
    failure = ["NONE", "NONE"]
    centre_out, ctrl_out, train_at = [], [], []
    steps = []
    for k, tk in enumerate(ticks):
        now = k * TICK_MS
        if tk["t"] != k:
            raise PipelineError(f"tick {k}: the model's time is {tk['t']}")
        train_at.append((tk["x"], tk["ph"]))
        # the centre
        ce = tk["centre"]
        if ce is None:
            raise PipelineError(f"tick {k}: centre output missing")
        start_acks, stop_acks, creports = [], [], []
        for u in tk["ua"]:
            src = k - u["age"]
            if src < 0:
                raise PipelineError(f"tick {k}: a controller telegram of tick {src}")
            o = ctrl_out[src][u["c"]]
            creports.append(o["report"])
            start_acks.extend(o["start_acks"])
            stop_acks.extend(o["stop_acks"])
        position = None
        if tk["pos"] is not None:
            src = k - tk["pos"]
            x, ph = train_at[src]
            position = {"train_id": TRAIN_ID, "time_ms": src * TICK_MS, "front_mm": ((x + 1) // 2) * CELL_MM,
                        "rear_mm": (x // 2 - b["train_len"]) * CELL_MM,
                        "speed_mm_s": 0 if ph == 1 else b["vmax"] * SPEED_MM_S}
        cc = []
        for c in (0, 1):
            d = ce["c"][c]
            cc.append({"crossing_id": CROSSING_IDS[c], "start_ms": _start_ms(d["st"], t), "start_pending": bool(d["p"]),
                       "acked": bool(d["a"]), "passed": bool(d["x"]), "stop_pending": bool(d["sp"]),
                       "stop_acked": bool(d["sa"]), "clock_fault": bool(d["cf"])})
        if any(not x["acked"] for x in cc):
            block = "MISSING_ACK"
        elif any(x["clock_fault"] for x in cc):
            block = "CLOCK_FAULT"
        elif now < t["GDWELL"] * TICK_MS:
            block = "BEFORE_DEPARTURE"
        else:
            block = "NONE"
        if (block == "NONE") != bool(ce["clr"]):
            raise PipelineError(f"tick {k}: departure signal {ce['clr']} disagrees with the centre state")
        cout = {"departure_cleared": bool(ce["clr"]), "block": block,
                "start_times": [{"crossing_id": x["crossing_id"], "departure_id": DEPARTURE_ID, "start_ms": x["start_ms"]}
                                for x in cc if x["start_pending"] and not x["passed"]],
                "warning_stops": [{"crossing_id": x["crossing_id"], "departure_id": DEPARTURE_ID}
                                  for x in cc if x["stop_pending"]],
                "crossings": cc}
        centre_out.append(cout)
        # the controllers
        ctrls, outs = [], []
        for c in (0, 1):
            g = tk["gctrl"].get(c)
            if g is None or c not in tk["bar"]:
                raise PipelineError(f"tick {k}: controller {c} output or barrier input missing")
            sts, stops = [], []
            for dm in tk["ds"]:
                if dm["c"] != c:
                    continue
                src = centre_out[k - dm["age"]]
                sts.extend(m for m in src["start_times"] if m["crossing_id"] == CROSSING_IDS[c])
                stops.extend(m for m in src["warning_stops"] if m["crossing_id"] == CROSSING_IDS[c])
            new_state = _controller_state(k, c, g, now, t, state, ws, failure)
            clock_state = CLOCK_STATES[g["ck"]]
            status = STATUS_OF[new_state]
            rep = _report(CROSSING_IDS[c], status, ws[c] if status != "OPEN" else 0, now, [],
                          clock_fault=clock_state == "FAULTY")
            sacks = [{"crossing_id": CROSSING_IDS[c], "departure_id": DEPARTURE_ID,
                      "start_ms": _start_ms(g["ack"] - 1, t), "stored": bool(g["acc"])}] if g["ack"] else []
            if len(sacks) != len(sts):
                raise PipelineError(f"tick {k}: controller {c}: {len(sts)} start time(s) but {len(sacks)} ack(s)")
            stacks = [{"crossing_id": CROSSING_IDS[c], "departure_id": DEPARTURE_ID}] if g["sack"] else []
            if len(stacks) != len(stops):
                raise PipelineError(f"tick {k}: controller {c}: stop acknowledgement disagrees with the stops")
            outs.append({"report": rep, "start_acks": sacks, "stop_acks": stacks})
            down, up = tk["bar"][c]
            ctrls.append({
                "crossing_id": CROSSING_IDS[c],
                "in": {"requests": [], "withdrawals": [], "barrier_down": bool(down), "barrier_up": bool(up),
                       "start_times": sts, "warning_stops": stops, "clock": CLOCK_INPUTS[tk["clk"].get(c, 0)]},
                "out": {"state": new_state, "warning_start_ms": ws[c] if new_state != "OPEN" else None,
                        "report": rep, "start_acks": sacks, "stop_acks": stacks,
                        "pending": {"present": bool(g["pres"]), "departure_id": DEPARTURE_ID if g["pres"] else None,
                                    "start_ms": _start_ms(g["pst"], t) if g["pres"] else None,
                                    "active": bool(g["act"])},
                        "clock": clock_state, "lights_on": new_state != "OPEN",
                        "barriers_down_commanded": new_state in ("CLOSING", "CLOSED", "FAILED"),
                        "failure": failure[c]}})
        ctrl_out.append(outs)
        steps.append({"t_ms": now,
                      "train": {"front_mm": tk["x"] * HALF_MM, "speed_mm_s": tk["v"] * SPEED_MM_S,
                                "at_station": tk["ph"] == 1},
                      "centre": {"in": {"start_acks": start_acks, "stop_acks": stop_acks, "reports": creports,
                                        "position": position},
                                 "out": cout},
                      "controllers": ctrls})
    return steps


# ---- the part -----------------------------------------------------------------------------------
class LevelCrossing(Part):
    """models/lc.pml: the on-board-requested warning."""
    prefix = "LC"
    configurations = (
        Configuration(None, walks=1),
        Configuration("LONG_WARNING", suffix=".long_warning", tag="LONGWARN-", walks=5),
        Configuration("TWO_TRAINS", suffix=".two_trains", tag="TWOTRAINS-", walks=5),
    )

    def bounds(self, model, params_pml):
        return all_bounds(model, params_pml)

    def parse_events(self, text):
        """Replay/simulation output -> list of ticks (dicts of the raw model integers). A tick
        begins with its @IN tick line and is complete with @OUT move; a tick cut off by the end of
        a trail or walk is dropped."""
        ticks, cur = [], None
        for kind, m, line in model_lines(text, _RX):
            g = [int(x) if x is not None else None for x in m.groups()]
            if kind == "tick":
                cur = {"t": g[0], "x": g[1], "v": g[2], "ph": g[3], "dw": g[4], "ul": [], "other": None, "bar": {},
                       "ctrl": {}, "rx": [], "board": None, "pos": None, "ua": [], "centre": None, "ds": [],
                       "clk": {}, "gctrl": {}}
                continue
            if cur is None:
                raise PipelineError(f"model output outside a tick: {line.strip()}")
            if kind == "ul":
                cur["ul"].append({"c": g[0], "age": g[1], "m": g[2]})
            elif kind == "other":
                cur["other"] = g[0]
            elif kind == "bar":
                cur["bar"][g[0]] = (g[1], g[2])
            elif kind == "ctrl":
                cur["ctrl"][g[0]] = {"cs": g[1], "wa": g[2], "new": g[3], "ack": g[4], "rq": g[5]}
            elif kind == "rx":
                cur["rx"].append({"c": g[0], "age": g[1]})
            elif kind == "board":
                cur["board"] = {"s": [g[0], g[1]], "e": [g[2], g[3]], "lim": g[4]}
            elif kind == "pos":
                cur["pos"] = g[0]
            elif kind == "ua":
                cur["ua"].append({"c": g[0], "age": g[1]})
            elif kind == "centre":
                cur["centre"] = {"clr": g[0],
                                 "c": [dict(zip(("st", "p", "a", "x", "sp", "sa", "cf"), g[1 + 7 * c:8 + 7 * c]))
                                       for c in (0, 1)]}
            elif kind == "ds":
                cur["ds"].append({"c": g[0], "age": g[1]})
            elif kind == "clk":
                cur["clk"][g[0]] = g[1]
            elif kind == "gctrl":
                cur["gctrl"][g[0]] = dict(zip(("cs", "wa", "new", "pres", "pst", "act", "ck", "ack", "acc", "sack"),
                                              g[1:]))
            elif kind == "move":
                cur["move"] = (g[0], g[1])
                ticks.append(cur)
                cur = None
        return ticks

    def to_steps(self, ticks, b, config):
        if VARIANT[config][0] == "GNSS":
            return gnss_steps(ticks, b, config)
        return onboard_steps(ticks, b, config)

    def observed_requirements(self, steps):
        """Requirements evidenced by what a run shows (added to a goal's own)."""
        reqs = set()
        for s in steps:
            for c in s["controllers"]:
                st = c["out"]["state"]
                if st != "OPEN":
                    reqs.add("REQ-LC-006")
                if st == "FAILED":
                    reqs.add("REQ-LC-014")
                if c["out"].get("start_acks"):
                    reqs.update(["REQ-LC-009", "REQ-LC-010"])
                if c["in"].get("warning_stops"):
                    reqs.add("REQ-LC-012")
                if c["in"].get("clock") in ("NO_GNSS", "FAULT"):
                    reqs.add("REQ-LC-013")
                if c["in"]["withdrawals"]:
                    reqs.update(["REQ-LC-004", "REQ-LC-007"])
            if "onboard" in s:
                reqs.add("REQ-LC-001")
                o = s["onboard"]["out"]
                if o["requests"]:
                    reqs.add("REQ-LC-002")
                if "CLEARED" in o["states"] or o["stop_limit_mm"] is not None:
                    reqs.add("REQ-LC-003")
                if o["withdrawals"]:
                    reqs.add("REQ-LC-004")
                if s["train"]["dwell"]:
                    reqs.add("REQ-LC-005")
            if "centre" in s:
                reqs.add("REQ-LC-008")
                if s["centre"]["out"]["departure_cleared"]:
                    reqs.add("REQ-LC-009")
                if s["centre"]["in"]["position"] is not None:
                    reqs.add("REQ-LC-010")
                if any(c["out"]["pending"]["active"] for c in s["controllers"]):
                    reqs.add("REQ-LC-011")
        return reqs

    def walk_length(self, b, config):
        return b["cycles"] if VARIANT[config][0] == "ONBOARD" else min(b["cycles"], b["gnss_horizon"])

    def header(self, target, config):
        b = target.bounds
        variant = VARIANT[config][0]
        t = timing(b, config)
        params = {
            "train": {"id": TRAIN_ID, "length_mm": b["train_len"] * CELL_MM, "accel_max_mm_s2": ACCEL_MM_S2},
            "other_train_id": OTHER_TRAIN_ID,
            "crossings": crossings(b, config),
            "restrictions": [{"begin_mm": 0, "end_mm": (b["track"] + 2) * CELL_MM,
                              "limit_mm_s": b["vmax"] * SPEED_MM_S}],
            "protection": {"request_lead_ms": t["LEAD"] * TICK_MS, "confirmation_max_age_ms": t["CMA"] * TICK_MS,
                           "protection_offset_mm": t["PO"] * CELL_MM, "lookahead_mm": 5_000_000},
            "controller": {"barrier_lowering_ms": t["LOWER"] * TICK_MS, "barrier_timeout_ms": t["TO"] * TICK_MS,
                           "max_warning_ms": MAX_WARNING_MS, "holdover_max_ms": t["HOLD"] * TICK_MS},
            "station": {"front_mm": b["station"] * CELL_MM,
                        "dwell_ms": (t["GDWELL"] if variant == "GNSS" else t["DWELL"]) * TICK_MS},
            "model_bounds": {k: b[k] for k in BOUNDS + LOCAL},
            "controller_states": CONTROLLER_STATES, "onboard_states": ONBOARD_STATES,
        }
        if variant == "GNSS":
            params["scheduler"] = {"clock_allowance_ms": 0}
            params["departure"] = {"train_id": TRAIN_ID, "departure_id": DEPARTURE_ID,
                                   "departure_ms": t["GDWELL"] * TICK_MS, "front_mm": b["station"] * CELL_MM,
                                   "started_at_ms": 0}
        return target.header(
            configuration=self.configuration(config).name, variant=variant, units=UNITS,
            unit_scales={"ms_per_tick": TICK_MS, "mm_per_cell": CELL_MM, "mm_per_half_cell": HALF_MM,
                         "mm_s_per_speed_unit": SPEED_MM_S, "mm_s2_per_accel_unit": ACCEL_MM_S2},
            parameters=params)


class LevelCrossingGnss(LevelCrossing):
    """models/lc_gnss.pml: the GNSS-time pre-armed crossings (same units, parser and steps)."""
    configurations = (
        Configuration("GNSS", tag="GNSS-", walks=5),
        Configuration("GNSS_CLOCK", suffix=".clock", tag="GNSSCLOCK-", walks=5),
    )


PARTS = {"lc": LevelCrossing(), "lc_gnss": LevelCrossingGnss()}
