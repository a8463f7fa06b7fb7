"""Tests of the level-crossing part of vector generation (railproof_testgen.capabilities.lc,
models/lc.pml and models/lc_gnss.pml, spec/schemas/vectors_lc.schema.json). The C++ conformance runner
(railproof_conformance_lc) is the behavioural check of the vectors; these tests check the parser,
the conversion to absolute times and C++ units, the ETA classes, header and schema on hand-made
model output, and that the vectors of a build (RAILPROOF_RESULTS_DIR) have a file per
configuration, follow design note §3-§5 and hit the boundaries."""
import re
from pathlib import Path

import pytest

from railproof_testgen import spin, vectors
from railproof_testgen.capabilities import lc
from railproof_testgen.capabilities.lc import PARTS
from railproof_testgen.errors import PipelineError
from vector_results import check_schema_cases, edited, vector_set

REPO = Path(__file__).resolve().parents[2]
MODEL = REPO / "models" / "lc.pml"            # the on-board-requested warning
MODEL_GNSS = REPO / "models" / "lc_gnss.pml"  # the GNSS-time pre-armed crossings
PART, PART_GNSS = PARTS["lc"], PARTS["lc_gnss"]
SCHEMA = REPO / "spec" / "schemas" / "vectors_lc.schema.json"

# the seeded C++ faults of cpp/runtime/lc/src/onboard/crossing_protection.cpp, cpp/runtime/lc/src/wayside/crossing_controller.cpp
# and cpp/runtime/lc/src/wayside/centre_scheduler.cpp, each mirrored by a mutant of the same name
CPP_FAULTS = ["CLEAR_WITHOUT_WARNING_TIME", "WITHDRAW_AT_FRONT", "STALE_CONFIRMATION", "END_WITH_REQUESTER",
              "DEPART_WITHOUT_ALL_ACKS", "LATER_UPDATE_WHILE_WARNING"]
CONFIG_NAMES = {"ONBOARD", "LONG_WARNING", "TWO_TRAINS", "FAIR", "HEALTHY", "GNSS", "GNSS_CLOCK", "GNSS_FAIR"}
BOUNDS = {"track": 12, "vmax": 2, "lc_a": 8, "lc_b": 10, "train_len": 1, "station": 4, "warn_ticks": 3,
          "lower_ticks": 1, "max_delay": 1, "cycles": 30, "lead_ticks": 3, "conf_age_ticks": 0, "prot_offset": 1,
          "dwell_ticks": 4, "gnss_dwell_ticks": 2, "holdover_ticks": 1, "response_ticks": 4, "gnss_horizon": 14,
          "gnss_faults": 2}


def test_annotations_of_the_level_crossing_models():
    anns = {m: spin.parse_annotations(m) for m in (MODEL, MODEL_GNSS)}
    props = {}
    for ann in anns.values():
        for p in ann.properties:  # a property of both models is the same claim, each with its configurations
            props.setdefault(p.name, []).append(p)
    assert {"REQ_LC_003_occupancy", "REQ_LC_003_fresh", "REQ_LC_007_end", "REQ_LC_007_ends", "REQ_LC_002_request",
            "REQ_LC_006_controller", "REQ_LC_015_no_braking", "REQ_LC_009_departure", "REQ_LC_008_start",
            "REQ_LC_013_clock", "REQ_LC_010_later"} == set(props)
    configs = {name: [c for p in ps for c in p.configs] for name, ps in props.items()}
    for name, ps in props.items():  # named by the requirement it verifies, in named configurations
        assert all(name[:10].replace("_", "-") in p.requirements for p in ps)
        assert configs[name] and set(configs[name]) <= CONFIG_NAMES
    # each model is checked in its own configurations only
    assert {c for p in anns[MODEL].properties for c in p.configs} == {"ONBOARD", "LONG_WARNING", "TWO_TRAINS",
                                                                      "FAIR", "HEALTHY"}
    assert {c for p in anns[MODEL_GNSS].properties for c in p.configs} == {"GNSS", "GNSS_CLOCK", "GNSS_FAIR"}
    # the occupancy property holds in both variants, the liveness is a bounded response under fairness
    assert {"ONBOARD", "GNSS"} <= set(configs["REQ_LC_003_occupancy"])
    assert set(configs["REQ_LC_007_ends"]) >= {"FAIR", "GNSS_FAIR"}
    assert configs["REQ_LC_015_no_braking"] == ["HEALTHY"]
    covered = {r for ps in props.values() for p in ps for r in p.requirements}
    assert covered == {f"REQ-LC-{n:03d}" for n in range(1, 16)}
    mutants = {m.name: (m, model) for model, ann in anns.items() for m in ann.mutants}
    assert {f"MUTANT_{f}" for f in CPP_FAULTS} <= set(mutants)
    assert len(mutants) > len(CPP_FAULTS)
    for f in CPP_FAULTS:  # each mutant names the C++ fault it mirrors
        assert f"FAULT_LC_{f}" in mutants[f"MUTANT_{f}"][0].text
    for m, model in mutants.values():  # checked in one configuration of its model where its property is verified
        own = {p.name: p for p in anns[model].properties}
        assert m.violates in own and m.config in own[m.violates].configs, m.name
    goals = [g for ann in anns.values() for g in ann.goals]
    assert len({g.number for g in goals}) == len(goals)  # goal numbers unique over both models
    assert all(g.requirements and g.label for g in goals)
    # every file gets trap vectors
    assert {g.config for g in anns[MODEL].goals} == {c.define for c in PART.configurations}
    assert {g.config for g in anns[MODEL_GNSS].goals} == {c.define for c in PART_GNSS.configurations}


def test_model_local_bounds_are_read_from_the_model():
    """The local bounds are in the parts both models share (models/include/lc_shared.pml)."""
    local = lc.model_local_defaults(MODEL)
    assert set(local) | {"dwell_ticks"} == set(lc.LOCAL)
    assert local["conf_age_ticks"] == 0 and local["lead_ticks"] >= 1 and local["gnss_faults"] >= 1
    assert lc.model_local_defaults(MODEL_GNSS) == local


def _model_eta2(d, v, vmax=2):
    """The model's eta_of (half-cells d, speed v): the first whole tick the run reaches d,
    minus a half-tick if it reaches it before."""
    if d <= 0:
        return 0
    r, t, s = 0, 0, v
    while r < d:
        n = min(s + 1, vmax)
        r, s, t = r + s + n, n, t + 1
    return 2 * t - (0 if r == d else 1)


def test_eta_classes_match_the_cpp_rounding():
    """Every ETA the model can compute has the same class as the C++'s ms value at the chosen
    tick length (design §2 rounding; the generator asserts the same on every vector)."""
    for d in range(0, 2 * BOUNDS["track"] + 1):
        for v in range(0, BOUNDS["vmax"] + 1):
            ms = lc.eta_ms(d * lc.HALF_MM, v * lc.SPEED_MM_S, lc.ACCEL_MM_S2,
                                   BOUNDS["vmax"] * lc.SPEED_MM_S)
            assert lc.eta_class(ms) == _model_eta2(d, v), (d, v, ms)
    # e.g. 4 cells from rest: accelerate 2 ticks, 2 cells at speed 2: exactly 3 ticks
    assert lc.eta_ms(4 * lc.CELL_MM, 0, lc.ACCEL_MM_S2, 2 * lc.SPEED_MM_S) == 30_000
    with pytest.raises(PipelineError, match="ETA class"):
        lc.check_eta(0, 0, 0, 16, 9, BOUNDS, "test")


# hand-made model output: two ticks of the ONBOARD model (a third cut off by the end of the
# trail) and two of the GNSS model
RUNS = Path(__file__).resolve().parent / "fixtures" / "lc"
ONBOARD_RUN = (RUNS / "onboard_run.txt").read_text(encoding="utf-8")
GNSS_RUN = (RUNS / "gnss_run.txt").read_text(encoding="utf-8")


def test_parse_and_convert_onboard_ticks():
    ticks = PART.parse_events(ONBOARD_RUN)
    assert len(ticks) == 2  # the third tick is cut off by the end of the trail
    assert ticks[1]["ul"] == [{"c": 0, "age": 0, "m": 1}]
    assert ticks[1]["rx"] == [{"c": 0, "age": 1}, {"c": 0, "age": 0}]
    steps = PART.to_steps(ticks, BOUNDS, None)
    s0, s1 = steps
    assert s0["t_ms"] == 0 and s1["t_ms"] == lc.TICK_MS
    assert s0["train"] == {"front_mm": 0, "speed_mm_s": 0, "dwell": False, "departure_ms": 0}
    assert s1["train"]["front_mm"] == 50_000 and s1["train"]["speed_mm_s"] == 10_000
    c0 = s1["controllers"][0]
    assert c0["in"] == {"requests": [1], "withdrawals": [], "barrier_down": False, "barrier_up": True}
    assert c0["out"]["state"] == "WARNING" and c0["out"]["warning_start_ms"] == 10_000
    assert c0["out"]["report"] == {"crossing_id": 1, "status": "WARNING", "warning_start_ms": 10_000,
                                   "issued_ms": 10_000, "clock_fault": False, "requesters": [1]}
    assert c0["out"]["requesters"] == [1] and c0["out"]["lights_on"] and not c0["out"]["barriers_down_commanded"]
    # the on-board unit receives tick 0's delayed report (age 1), then tick 1's, in that order
    reps = s1["onboard"]["in"]["reports"]
    assert [(r["status"], r["issued_ms"]) for r in reps] == [("OPEN", 0), ("WARNING", 10_000)]
    out = s0["onboard"]["out"]
    assert out["states"] == ["REQUESTED", "REQUESTED"] and out["eta_half_ticks"] == [10, 12]
    assert out["requests"] == [1, 2] and out["withdrawals"] == [] and out["stop_limit_mm"] == 14 * 50_000
    assert PART.observed_requirements(steps) >= {"REQ-LC-001", "REQ-LC-002", "REQ-LC-003", "REQ-LC-006"}


def test_parse_and_convert_gnss_ticks():
    steps = PART.to_steps(PART.parse_events(GNSS_RUN), BOUNDS, "GNSS")
    s0, s1 = steps
    t = lc.timing(BOUNDS, "GNSS")
    assert t["OFS"] == 6
    ce = s0["centre"]
    # the standing train's report: front and rear on whole cells, speed bound 0 at the station
    assert ce["in"]["position"] == {"train_id": 1, "time_ms": 0, "front_mm": 400_000, "rear_mm": 300_000,
                                    "speed_mm_s": 0}
    # initial start times: t_dep (2 ticks) + ETA from rest (3 and 4 ticks) - W (3 ticks)
    assert [x["start_ms"] for x in ce["out"]["crossings"]] == [20_000, 30_000]
    assert ce["out"]["start_times"] == [{"crossing_id": 1, "departure_id": 1, "start_ms": 20_000},
                                        {"crossing_id": 2, "departure_id": 1, "start_ms": 30_000}]
    assert ce["out"]["block"] == "MISSING_ACK" and not ce["out"]["departure_cleared"]
    c0 = s0["controllers"][0]
    assert c0["in"]["start_times"] == [{"crossing_id": 1, "departure_id": 1, "start_ms": 20_000}]
    assert c0["out"]["start_acks"] == [{"crossing_id": 1, "departure_id": 1, "start_ms": 20_000, "stored": True}]
    assert c0["out"]["pending"] == {"present": True, "departure_id": 1, "start_ms": 20_000, "active": False}
    assert s0["controllers"][1]["in"]["clock"] == "NO_GNSS" and s0["controllers"][1]["out"]["clock"] == "HOLDOVER"
    # tick 1: the centre receives controller A's telegram of tick 0 (ack, report)
    assert s1["centre"]["in"]["start_acks"] == c0["out"]["start_acks"]
    assert s1["centre"]["in"]["reports"] == [c0["out"]["report"]]
    assert s1["centre"]["in"]["position"] is None
    assert s1["centre"]["out"]["start_times"] == [{"crossing_id": 2, "departure_id": 1, "start_ms": 30_000}]


def test_malformed_model_output_is_an_error():
    with pytest.raises(PipelineError, match="unrecognised"):
        PART.parse_events("@OUT level=1 appr=0 latched=0")
    with pytest.raises(PipelineError, match="outside a tick"):
        PART.parse_events("@OUT ctrl c=0 cs=0 wa=0 new=0 ack=0 rq=0")
    bad = ONBOARD_RUN.replace("@OUT ctrl c=0 cs=1 wa=0 new=1 ack=0 rq=1", "@OUT ctrl c=0 cs=1 wa=0 new=1 ack=0 rq=0")
    with pytest.raises(PipelineError, match="requester tracking"):
        PART.to_steps(PART.parse_events(bad), BOUNDS, None)
    bad = ONBOARD_RUN.replace("e0=8 e1=10", "e0=7 e1=10")
    with pytest.raises(PipelineError, match="ETA class"):
        PART.to_steps(PART.parse_events(bad), BOUNDS, None)
    bad = GNSS_RUN.replace("@OUT centre clr=0 st0=10 p0=0 a0=1", "@OUT centre clr=1 st0=10 p0=0 a0=1")
    with pytest.raises(PipelineError, match="departure signal"):
        PART.to_steps(PART.parse_events(bad), BOUNDS, "GNSS")


def _header(config=None):
    part, model = (PART_GNSS, MODEL_GNSS) if config and config.startswith("GNSS") else (PART, MODEL)
    return part.header(vectors.Target(model, spin.parse_annotations(model), BOUNDS, "test"), config)


def test_header_records_the_configuration_and_units():
    h, hl, hg = _header(), _header("LONG_WARNING"), _header("GNSS")
    assert h["configuration"] == "default" and h["variant"] == "ONBOARD" and hg["variant"] == "GNSS"
    assert h["model"] == "models/lc.pml" and hg["model"] == "models/lc_gnss.pml"
    p = h["parameters"]
    assert [c["warning_time_ms"] for c in p["crossings"]] == [30_000, 30_000]
    assert [c["warning_time_ms"] for c in hl["parameters"]["crossings"]] == [40_000, 40_000]
    assert p["crossings"][0]["near_mm"] == 800_000 and p["crossings"][0]["far_mm"] == 900_000
    assert p["protection"]["request_lead_ms"] == 30_000 and p["protection"]["confirmation_max_age_ms"] == 0
    assert p["controller"]["barrier_timeout_ms"] == 20_000 and hl["parameters"]["controller"]["barrier_timeout_ms"] == 30_000
    assert p["restrictions"] == [{"begin_mm": 0, "end_mm": 1_400_000, "limit_mm_s": 20_000}]
    assert "departure" not in p and hg["parameters"]["departure"]["departure_ms"] == 20_000
    assert h["unit_scales"]["mm_s2_per_accel_unit"] == 1000 and h["units"] == lc.UNITS


def _vector(config=None, run=ONBOARD_RUN, vid="LC-TRAP-G0"):
    steps = PART.to_steps(PART.parse_events(run), BOUNDS, config)
    return {"id": vid, "requirements": ["REQ-LC-002"], "goal": "G0", "kind": "trap", "seed": None, "steps": steps}


def test_schema_accepts_good_and_rejects_bad_records():
    good = [_header(), _vector()]
    vectors.sealed_jsonl(SCHEMA, _header("GNSS"), [_vector("GNSS", GNSS_RUN, "LC-TRAP-GNSS-G60")], "lc_gnss.jsonl")
    check_schema_cases(SCHEMA, good, "lc.jsonl", {
        "units": lambda ls: ls[0].update(units="ticks"),
        "tick length": lambda ls: ls[0]["unit_scales"].update(ms_per_tick=1000),
        "unknown configuration": lambda ls: ls[0].update(configuration="THREE_TRAINS"),
        "GNSS parameters in an ONBOARD file": lambda ls: ls[0]["parameters"].update(scheduler={"clock_allowance_ms": 0}),
        "GNSS variant without departure": lambda ls: ls[0].update(variant="GNSS", configuration="GNSS"),
        "crossing missing": lambda ls: ls[0]["parameters"]["crossings"].pop(),
        "bad vector id": lambda ls: ls[1].update(id="RA-TRAP-G0"),
        "requirement of another area": lambda ls: ls[1].update(requirements=["REQ-RA-003"]),
        "unknown controller state": lambda ls: ls[1]["steps"][0]["controllers"][0]["out"].update(state="LOWERING"),
        "unknown on-board state": lambda ls: ls[1]["steps"][0]["onboard"]["out"].update(states=["GO", "GO"]),
        "report status": lambda ls: ls[1]["steps"][1]["onboard"]["in"]["reports"][0].update(status="OPENING"),
        "output field missing": lambda ls: ls[1]["steps"][0]["onboard"]["out"].pop("stop_limit_mm"),
        "extra input": lambda ls: ls[1]["steps"][0]["train"].update(accel=1),
        "one controller": lambda ls: ls[1]["steps"][0]["controllers"].pop(),
        "no steps": lambda ls: ls[1].update(steps=[]),
    })
    # the message names the field inside the vector (not the whole line) and stays short
    no_list = edited(good, lambda ls: ls[1]["steps"][0]["onboard"]["in"]["reports"][0].pop("requesters"))
    with pytest.raises(PipelineError) as info:
        vectors.sealed_jsonl(SCHEMA, no_list[0], no_list[1:], "lc.jsonl")
    assert "'requesters' is a required property" in str(info.value)
    assert re.search(r"line 2 violates the vector schema: steps/0/\S*reports?\S*: ", str(info.value)), info.value
    assert len(str(info.value)) < 500


@pytest.mark.parametrize("model, part", [("lc", PART), ("lc_gnss", PART_GNSS)])
def test_every_configuration_has_its_file(model, part):
    vs = vector_set(model)
    assert sorted(vs.files) == sorted(f"{model}{c.suffix}.jsonl" for c in part.configurations)
    for c in part.configurations:
        name = f"{model}{c.suffix}.jsonl"
        header = vs.header(name)
        assert header["model"] == f"models/{model}.pml"
        assert header["configuration"] == c.name and header["variant"] == lc.VARIANT[c.define][0]
        walks = [v for v in vs.vectors(name) if v["kind"] == "random"]
        assert walks and all(len(v["steps"]) == part.walk_length(header["parameters"]["model_bounds"], c.define)
                             for v in walks)
        for v in vs.vectors(name):
            assert v["id"].startswith(f"LC-{v['kind'].upper()}-{c.tag}"), v["id"]
    goals = {g["id"]: g for g in vs.coverage["goals"]}
    assert all(g["configuration"] in {c.name for c in part.configurations} for g in goals.values())


def test_vectors_follow_the_design_note():
    """Invariants of design note §3-§5 on every step of every vector (the exact values are the
    C++ conformance runner's check)."""
    files = {**vector_set("lc").files, **vector_set("lc_gnss").files}
    assert any(n.startswith("lc_gnss") for n in files) and "lc.jsonl" in files
    for name, lines in files.items():
        h = lines[0]["parameters"]
        near = {c["id"]: c["near_mm"] for c in h["crossings"]}
        offset = h["protection"]["protection_offset_mm"]
        for v in lines[1:]:
            prev_t = -1
            for s in v["steps"]:
                assert s["t_ms"] == prev_t + 10_000 or (prev_t < 0 and s["t_ms"] == 0)
                prev_t = s["t_ms"]
                for c in s["controllers"]:
                    o = c["out"]
                    assert o["report"]["status"] == lc.STATUS_OF[o["state"]]
                    assert o["report"]["issued_ms"] == s["t_ms"]
                    assert o["lights_on"] == (o["state"] != "OPEN")
                    assert (o["failure"] != "NONE") == (o["state"] == "FAILED")
                    if o["state"] == "CLOSED":  # REQ-LC-006: closed only while detected down
                        assert c["in"]["barrier_down"] and not c["in"]["barrier_up"]
                if "onboard" in s:
                    o = s["onboard"]["out"]
                    # REQ-LC-002/-004: requests for REQUESTED/CLEARED, withdrawals for PASSED
                    assert o["requests"] == [cid for cid, st in zip((1, 2), o["states"]) if st in ("REQUESTED", "CLEARED")]
                    assert o["withdrawals"] == [cid for cid, st in zip((1, 2), o["states"]) if st == "PASSED"]
                    # REQ-LC-003: the most restrictive limit of the crossings not cleared
                    limits = [near[cid] - offset for cid, st in zip((1, 2), o["states"])
                              if st in ("APPROACHING", "REQUESTED")]
                    assert o["stop_limit_mm"] == (min(limits) if limits else None)
                    # REQ-LC-004: a withdrawal only once the rear has passed the far edge
                    for cid, st in zip((1, 2), o["states"]):
                        if st == "PASSED":
                            far = next(c["far_mm"] for c in h["crossings"] if c["id"] == cid)
                            assert s["train"]["front_mm"] - h["train"]["length_mm"] >= far
                    for r in s["onboard"]["in"]["reports"]:  # reports come from the past
                        assert r["issued_ms"] <= s["t_ms"]
                else:
                    o = s["centre"]["out"]
                    # REQ-LC-009: the departure signal only with every acknowledgement, no fault, t_dep
                    assert o["departure_cleared"] == (all(c["acked"] for c in o["crossings"]) and
                                                      not any(c["clock_fault"] for c in o["crossings"]) and
                                                      s["t_ms"] >= h["departure"]["departure_ms"])
                    pos = s["centre"]["in"]["position"]
                    if pos is not None:
                        assert pos["time_ms"] <= s["t_ms"] and pos["rear_mm"] < pos["front_mm"]


def test_boundary_vectors_hit_the_boundaries():
    vs = vector_set("lc")
    t = lc.timing(vs.header("lc.jsonl")["parameters"]["model_bounds"], None)
    vecs = vs.by_goal("lc.jsonl")
    last = {g: v["steps"][-1] for g, v in vecs.items()}
    # G0/G1: the request exactly at ETA = W + LEAD, none half a tick above
    assert last["G0"]["onboard"]["out"]["states"][0] == "REQUESTED"
    assert last["G0"]["onboard"]["out"]["eta_half_ticks"][0] == 2 * (t["W"] + t["LEAD"])
    assert last["G1"]["onboard"]["out"]["states"][0] == "APPROACHING"
    assert last["G1"]["onboard"]["out"]["eta_half_ticks"][0] == 2 * (t["W"] + t["LEAD"]) + 2
    # G2: requested in the dwell, the remaining dwell counted
    s = last["G2"]
    assert s["train"]["dwell"] and s["train"]["departure_ms"] > s["t_ms"]
    assert s["onboard"]["out"]["eta_half_ticks"][0] == 2 * (t["W"] + t["LEAD"])
    # G5: a CLOSED report one tick older than the confirmation age does not clear
    s = last["G5"]
    of_a = [r for r in s["onboard"]["in"]["reports"] if r["crossing_id"] == 1]
    assert [r["status"] for r in of_a] == ["CLOSED"] and of_a[0]["requesters"] == [1]
    assert of_a[0]["issued_ms"] == s["t_ms"] - 10_000
    assert s["onboard"]["out"]["states"][0] == "REQUESTED"
    # G10: stuck barrier: FAILED exactly at ws + LOWER + TO
    c = last["G10"]["controllers"][0]["out"]
    assert c["state"] == "FAILED" and c["failure"] == "BARRIER_NOT_DOWN"
    assert last["G10"]["t_ms"] - c["warning_start_ms"] == (t["LOWER"] + t["TO"]) * 10_000
    # G17: the rear exactly at the far edge: PASSED and withdrawn
    s = last["G17"]
    assert s["onboard"]["out"]["states"][0] == "PASSED" and s["onboard"]["out"]["withdrawals"] == [1]
    assert s["train"]["front_mm"] - 100_000 == 900_000
    # LONG_WARNING G4: CLOSED for the train but warned too short: no clearance
    lw = vs.by_goal("lc.long_warning.jsonl")
    s = lw["G4"]["steps"][-1]
    assert s["onboard"]["out"]["states"][0] == "REQUESTED"
    assert any(r["status"] == "CLOSED" for r in s["onboard"]["in"]["reports"])
    # GNSS G60: autonomous start exactly at the stored start time
    gv = vector_set("lc_gnss").by_goal("lc_gnss.jsonl")
    s = gv["G60"]["steps"][-1]["controllers"][0]
    assert s["out"]["state"] == "WARNING" and s["out"]["pending"]["start_ms"] == gv["G60"]["steps"][-1]["t_ms"]
    # GNSS G100: the train leaves exactly at t_dep on the signal
    s = gv["G100"]["steps"][-1]
    assert s["centre"]["out"]["departure_cleared"] and s["t_ms"] == 2 * 10_000
