"""Tests of the re-adhesion part of vector generation: the state machine
(railproof_testgen.capabilities.ra, models/ra.pml, spec/schemas/vectors_ra.schema.json). The C++
conformance runner (railproof_conformance_ra) is the behavioural check of the vectors; these
tests check the parser, conversion, header and schema on hand-made model output, and that the
vectors of a build (RAILPROOF_RESULTS_DIR) cover both machine configurations, follow design
note §5 and hit the boundaries."""
import json
from pathlib import Path


import pytest

from railproof_testgen import spec, spin, vectors
from railproof_testgen.capabilities import ra
from railproof_testgen.capabilities.ra import PART
from railproof_testgen.errors import PipelineError
from vector_results import check_schema_cases, vector_set

REPO = Path(__file__).resolve().parents[2]
MODEL = REPO / "models" / "ra.pml"
SCHEMA = REPO / "spec" / "schemas" / "vectors_ra.schema.json"

# the seeded C++ faults of cpp/runtime/ra/src/readhesion_machine.cpp, each mirrored by a mutant
CPP_FAULTS = ["TIMEOUT_OFF_BY_ONE", "CONFIRM_TWO", "SPEED_IGNORED", "EPISODE_RELAXES", "LAST_CANDIDATE_WINS",
              "TG_FAILURE_IGNORED", "TRUST_KEPT_ON_DEVIATION"]
BOUNDS = {"confirm": 3, "start_age": 2, "search_extra": 1, "spacing": 2, "tmax_long": 9, "tmax_short": 6,
          "margin_long": 2, "margin_steep": 3, "margin_short": 1, "warmup": 2, "cycles": 16}


def test_annotations_of_the_readhesion_model():
    ann = spin.parse_annotations(MODEL)
    props = {p.name: p for p in ann.properties}
    assert set(props) == {"REQ_RA_003_detection", "REQ_RA_004_start_point", "REQ_RA_006_readhesion", "REQ_RA_007_timeout",
                          "REQ_RA_007_stopped", "REQ_RA_009_limits", "REQ_RA_010_parallel", "REQ_RA_012_balise",
                          "REQ_RA_013_sensor", "REQ_RA_015_startup"}
    for name, p in props.items():  # named by the requirement it verifies, default configuration
        assert name[:10].replace("_", "-") in p.requirements
        assert p.config is None
    covered = {r for p in ann.properties for r in p.requirements}
    assert covered == {"REQ-RA-003", "REQ-RA-004", "REQ-RA-006", "REQ-RA-007", "REQ-RA-009", "REQ-RA-010", "REQ-RA-012",
                       "REQ-RA-013", "REQ-RA-015"}
    # the one-start-point configuration: a variant, so every property is verified in it too
    assert [(v.define, v.parameter, v.bound) for v in ann.variants] == [("ONE_START", "start_points", "1")]
    assert [c.define for c in PART.configurations] == [None, "ONE_START", "UNIT"]
    # the unit's environment: random walks only (neither verified nor searched)
    assert [d for d, _ in ann.walk_only] == ["UNIT"]
    mutants = {m.name: m for m in ann.mutants}
    assert {f"MUTANT_{f}" for f in CPP_FAULTS} <= set(mutants)
    assert len(mutants) > len(CPP_FAULTS)
    for f in CPP_FAULTS:  # each mutant names the C++ fault it mirrors
        assert f"FAULT_RA_{f}" in mutants[f"MUTANT_{f}"].text
    assert all(m.violates in props and m.config is None for m in ann.mutants)
    assert [g.number for g in ann.goals] == list(range(len(ann.goals)))
    assert all(g.requirements and g.label for g in ann.goals)
    assert {g.config for g in ann.goals} == {None, "ONE_START"}


def _cycle(dev=0, sa=(0, 0), imu=1, tg=1, bal=0, mv=0, sec=0, age=2, **out):
    o = {"mode": 0, "reason": 0, "dcount": 0, "a0": 0, "t0": 0, "c0": 0, "a1": 0, "t1": 0, "c1": 0, "tmax": 9,
         "margin": 2, "stop": 0, "valid": 1, "det": 0, "adopted": 255, "breset": 0, "trust": 1, "rest": 0}
    o.update(out)
    return [f"  @IN cycle dev={dev} sa0={sa[0]} sa1={sa[1]} imu={imu} tg={tg} bal={bal} mv={mv} sec={sec} age={age}",
            "  @OUT " + " ".join(f"{k}={v}" for k, v in o.items())]


def test_parse_events_and_steps():
    text = "\n".join(
        ["spin: some unrelated line"]
        + _cycle(dev=1, sec=1, age=3, mode=1, a0=1, t0=3, a1=1, t1=5, margin=3, det=1, breset=0)
        + _cycle(sa=(1, 0), sec=2, mode=0, tmax=6, margin=3, adopted=0)
        + _cycle(imu=0, tg=0, bal=1, mode=2, reason=2, tmax=9, stop=1, valid=0, trust=0)
        + _cycle(mv=1, mode=2, reason=5, stop=1, valid=0, trust=0)
        + ["  @IN cycle dev=0 sa0=0 sa1=0 imu=1 tg=1 bal=0 mv=0 sec=0 age=2"])  # cut off by the end of a trail
    ev = PART.parse_events(text)
    assert len(ev) == 4
    assert ev[0][0] == {"dev": True, "sa": [False, False], "imu": True, "tg": True, "bal": False, "mv": False,
                        "sec": 1, "age": 3}
    steps = PART.to_steps(ev, BOUNDS, None)
    assert steps[0] == {
        "in": {"deviation": True, "speed_agrees": [False, False], "imu_ok": True, "tg_ok": True, "balise": False,
               "tg_moving": False, "section": {"kind": "STEEP", "max_compensation_cycles": 9, "margin_mm": 3},
               "start_age_cycles": 3},
        "out": {"mode": "COMPENSATING", "stop_reason": "NONE", "deviation_count": 0,
                "candidates": [{"active": True, "age_cycles": 3, "confirm": 0},
                               {"active": True, "age_cycles": 5, "confirm": 0}],
                "max_compensation_cycles": 9, "margin_mm": 3, "stop_demand": False, "position_valid": True,
                "trusted": True, "rest_cycles": 0, "detected": True, "adopted": None, "balise_reset": False}}
    assert steps[1]["in"]["section"] == {"kind": "TIGHT", "max_compensation_cycles": 6, "margin_mm": 1}
    assert steps[1]["in"]["speed_agrees"] == [True, False]
    assert steps[1]["out"]["adopted"] == 0 and steps[1]["out"]["mode"] == "TG"
    assert steps[2]["out"]["stop_reason"] == "IMU_FAILURE" and steps[2]["out"]["stop_demand"]
    assert not steps[2]["in"]["imu_ok"] and steps[2]["in"]["balise"] and not steps[2]["out"]["trusted"]
    assert steps[3]["in"]["tg_moving"] and steps[3]["out"]["stop_reason"] == "START_IN_MOTION"
    assert PART.observed_requirements(steps) == {"REQ-RA-003", "REQ-RA-004", "REQ-RA-006", "REQ-RA-009", "REQ-RA-010",
                                                        "REQ-RA-013", "REQ-RA-015"}
    assert PART.observed_requirements([]) == set()


def test_malformed_model_output_is_an_error():
    with pytest.raises(PipelineError, match="without its @IN cycle"):
        PART.parse_events(_cycle()[1])
    with pytest.raises(PipelineError, match="unrecognised"):
        PART.parse_events("@OUT level=1 appr=0 latched=0")
    with pytest.raises(PipelineError, match="unknown adopted"):
        PART.to_steps(PART.parse_events("\n".join(_cycle(adopted=7))), BOUNDS, None)
    with pytest.raises(PipelineError, match="outside the known"):
        PART.to_steps(PART.parse_events("\n".join(_cycle(sec=3))), BOUNDS, None)


def _header(config=None):
    return PART.header(vectors.Target(MODEL, spin.parse_annotations(MODEL), BOUNDS, "test"), config)


def _vector():
    steps = PART.to_steps(PART.parse_events("\n".join(
        _cycle(dev=1, mode=1, a0=1, t0=2, a1=1, t1=4, det=1))), BOUNDS, None)
    return {"id": "RA-TRAP-G0", "requirements": ["REQ-RA-003"], "goal": "G0", "kind": "trap", "seed": None,
            "steps": steps}


def test_header_records_the_machine_configuration():
    h, h1 = _header(), _header("ONE_START")
    assert h["configuration"] == "default" and h1["configuration"] == "ONE_START"
    assert h["parameters"]["start_points"] == 2 and h1["parameters"]["start_points"] == 1
    assert h["parameters"]["confirm_cycles"] == 3 and h["parameters"]["spacing_cycles"] == 2
    assert h["parameters"]["warmup_cycles"] == 2
    assert h["parameters"]["start_age_cycles"] == [2, 3]
    assert h["units"] == ra.UNITS == "model ticks = cycles, model margin units = mm"
    assert [s["kind"] for s in h["parameters"]["sections"]] == ra.SECTIONS


def test_schema_accepts_good_and_rejects_bad_records():
    vectors.sealed_jsonl(SCHEMA, _header("ONE_START"), [{**_vector(), "id": "RA-TRAP-ONESTART-G0"}],
                         "ra.one_start.jsonl")
    check_schema_cases(SCHEMA, [_header(), _vector()], "ra.jsonl", {
        "units": lambda ls: ls[0].update(units="cycles"),
        "configuration and start points disagree": lambda ls: ls[0]["parameters"].update(start_points=1),
        "unknown configuration": lambda ls: ls[0].update(configuration="THREE_START"),
        "machine parameter missing": lambda ls: ls[0]["parameters"].pop("spacing_cycles"),
        "bad vector id": lambda ls: ls[1].update(id="BR-TRAP-G0"),
        "no requirement": lambda ls: ls[1].update(requirements=[]),
        "unknown mode": lambda ls: ls[1]["steps"][0]["out"].update(mode="SLIPPING"),
        "adopted out of range": lambda ls: ls[1]["steps"][0]["out"].update(adopted=2),
        "output field missing": lambda ls: ls[1]["steps"][0]["out"].pop("balise_reset"),
        "extra input field": lambda ls: ls[1]["steps"][0]["in"].update(speed=3),
        "one speed agreement only": lambda ls: ls[1]["steps"][0]["in"].update(speed_agrees=[True]),
        "section time zero": lambda ls: ls[1]["steps"][0]["in"]["section"].update(max_compensation_cycles=0),
        "three candidates": lambda ls: ls[1]["steps"][0]["out"]["candidates"].append(
            {"active": False, "age_cycles": 0, "confirm": 0}),
        "no steps": lambda ls: ls[1].update(steps=[]),
    })


def test_both_machine_configurations_have_their_file():
    vs = vector_set("ra")
    assert sorted(vs.files) == ["ra.jsonl", "ra.one_start.jsonl", "ra.unit.jsonl"]
    for name in ("ra.jsonl", "ra.one_start.jsonl"):
        one = name == "ra.one_start.jsonl"
        header = vs.header(name)
        assert header["configuration"] == ("ONE_START" if one else "default")
        assert header["parameters"]["start_points"] == (1 if one else 2)
        assert all(("ONESTART-" in v["id"]) == one for v in vs.vectors(name))
        assert any(v["kind"] == "random" for v in vs.vectors(name))
        assert all(len(v["steps"]) == header["parameters"]["model_cycles"] for v in vs.vectors(name)
                   if v["kind"] == "random")
    goals = vs.coverage["goals"]
    one_start = [g for g in goals if g["configuration"] == "ONE_START"]
    assert one_start and all(g["status"] == "reached" for g in one_start)
    # the default configuration's goals searched in ONE_START too: their vectors in the one-start file
    ids = {v["id"] for v in vs.vectors("ra.one_start.jsonl")}
    variant = [x for g in goals for x in g.get("variant_vectors", [])]
    assert variant and set(variant) <= ids


def test_unit_set_is_the_unit_environment():
    """ra.unit.jsonl (variant UNIT): the unit's times in the header, 50 walks of
    MODEL_UNIT_CYCLES cycles, and in every vector the input sequences the on-board unit's sensor
    stream can give (models/ra.pml, unit_inputs): one section, at most one detection, a start-point
    age the search can find at the cycle's history index, no TG motion in a history's first cycle,
    the primary agreeing only with the second (both alike where their start points are one)."""
    vs = vector_set("ra")
    h = vs.header("ra.unit.jsonl")
    assert h["configuration"] == "UNIT"
    # the header's times are the model_unit_* bounds, which are the runtime's times (spec/parameters/ra.yaml)
    area = spec.load_parameters(REPO / "spec")["RA"]
    bound = {k.removeprefix("model_unit_"): e["value"] for k, e in area["model_bounds"].items()
             if k.startswith("model_unit_")}
    rt = {k: e["value"] for k, e in area["parameters"].items()}
    cycle = rt["cycle_ms"]
    assert (bound["start_age"], bound["search_extra"], bound["spacing"], bound["warmup"], bound["tmax_short"]) == (
        rt["lookback_ms"] // cycle, rt["search_depth_ms"] // cycle, rt["parallel_spacing_ms"] // cycle,
        (rt["moving_average_ms"] + rt["tg_window_ms"]) // cycle, rt["min_compensation_ms"] // cycle)
    p = h["parameters"]
    assert (p["spacing_cycles"], p["warmup_cycles"], p["start_age_cycles"], p["model_cycles"]) == (
        bound["spacing"], bound["warmup"], [bound["start_age"], bound["start_age"] + bound["search_extra"]],
        bound["cycles"])
    assert [s["max_compensation_cycles"] for s in p["sections"]] == [bound["tmax_long"]] * 2 + [bound["tmax_short"]]
    vecs = vs.vectors("ra.unit.jsonl")
    assert len(vecs) == 50 and all(v["kind"] == "random" and v["id"].startswith("RA-RANDOM-UNIT-S") for v in vecs)
    detections = 0
    for v in vecs:
        steps = v["steps"]
        assert len(steps) == bound["cycles"]
        assert len({json.dumps(s["in"]["section"], sort_keys=True) for s in steps}) == 1, v["id"]
        index, same, seen = 0, False, 0
        for k, s in enumerate(steps):
            i, o = s["in"], s["out"]
            if index == 0:
                assert not i["tg_moving"], (v["id"], k)
            if o["detected"]:
                seen += 1
                age = i["start_age_cycles"]
                oldest = index - bound["warmup"]  # the oldest usable history entry's age
                age_top = bound["start_age"] + bound["search_extra"]
                found = bound["start_age"] <= age <= min(age_top, oldest - h["parameters"]["confirm_cycles"])
                assert age == min(age_top, oldest) or found, (v["id"], k, age, index)
                same = age == oldest
            if o["mode"] == "COMPENSATING" or steps[k - 1]["out"]["mode"] == "COMPENSATING" if k else False:
                sa = i["speed_agrees"]
                assert not sa[0] or sa[1], (v["id"], k)
                assert not same or sa[0] == sa[1], (v["id"], k)
            index = index + 1 if i["imu_ok"] and i["tg_ok"] else 0
        assert seen <= 1, v["id"]
        detections += seen
    assert detections > 25


def test_vectors_follow_the_design_note():
    """Invariants of design note §5 on every step of every vector (the exact values are the
    C++ conformance runner's check)."""
    vs = vector_set("ra")
    for name, lines in vs.files.items():
        spacing = lines[0]["parameters"]["spacing_cycles"]
        points = lines[0]["parameters"]["start_points"]
        for v in lines[1:]:
            prev = "TG"
            for s in v["steps"]:
                i, o = s["in"], s["out"]
                stopped = o["mode"] == "STOPPED"
                assert o["stop_demand"] == stopped and o["position_valid"] == (not stopped), v["id"]
                assert (o["stop_reason"] != "NONE") == stopped
                if not (i["imu_ok"] and i["tg_ok"]):  # REQ-RA-013: the safe reaction in the same cycle
                    assert o["stop_reason"] == ("IMU_FAILURE" if not i["imu_ok"] else "TG_FAILURE")
                    assert not any(c["active"] for c in o["candidates"])
                if points == 1:
                    assert not o["candidates"][1]["active"]
                for c in o["candidates"]:  # REQ-RA-007: never beyond t_max
                    assert not c["active"] or c["age_cycles"] <= o["max_compensation_cycles"]
                    assert c["active"] or (c["age_cycles"], c["confirm"]) == (0, 0)
                if o["adopted"] is not None:  # REQ-RA-010: nothing active after the adoption
                    assert o["mode"] == "TG" and not any(c["active"] for c in o["candidates"])
                if prev != "COMPENSATING":  # REQ-RA-009: outside an episode the section's limits
                    assert o["margin_mm"] == i["section"]["margin_mm"]
                    assert o["max_compensation_cycles"] == i["section"]["max_compensation_cycles"]
                else:
                    assert o["margin_mm"] >= i["section"]["margin_mm"]
                    assert o["max_compensation_cycles"] <= i["section"]["max_compensation_cycles"]
                if o["balise_reset"]:  # REQ-RA-012
                    assert i["balise"] and prev != "COMPENSATING"
                if o["detected"]:  # REQ-RA-004/010: ages from the start point, too old discarded
                    t_max = o["max_compensation_cycles"]
                    for k in range(points):
                        age = i["start_age_cycles"] + k * spacing
                        c = o["candidates"][k]
                        if age <= t_max:
                            assert c["active"] or o["mode"] != "COMPENSATING"
                            assert not c["active"] or c["age_cycles"] == age
                        else:
                            assert not c["active"] and c["age_cycles"] == 0
                prev = o["mode"]


def test_boundary_vectors_hit_the_boundaries():
    vs = vector_set("ra")
    vecs = vs.by_goal("ra.jsonl")
    confirm = vs.header("ra.jsonl")["parameters"]["confirm_cycles"]
    last = {g: v["steps"][-1] for g, v in vecs.items()}
    # G12: compensating at exactly t_max; G13: the last candidate discarded at t_max + 1
    o = last["G12"]["out"]
    assert o["mode"] == "COMPENSATING" and o["candidates"][0]["age_cycles"] == o["max_compensation_cycles"]
    before, o = vecs["G13"]["steps"][-2]["out"], last["G13"]["out"]
    assert o["stop_reason"] == "MAX_COMPENSATION_TIME" and o["stop_demand"] and not o["position_valid"]
    assert before["candidates"][0]["age_cycles"] == o["max_compensation_cycles"]  # one more cycle: t_max + 1
    # G4: adoption exactly MODEL_CONFIRM cycles after the detection; G10: both confirm, primary wins
    det = next(k for k, s in enumerate(vecs["G4"]["steps"]) if s["out"]["detected"])
    assert len(vecs["G4"]["steps"]) - 1 - det == confirm and last["G4"]["out"]["adopted"] == 0
    assert last["G10"]["in"]["speed_agrees"] == [True, True] and last["G10"]["out"]["adopted"] == 0
    assert last["G8"]["out"]["adopted"] == 1
    # G6: the speed condition alone restarts the confirmation
    s = last["G6"]
    assert not s["in"]["deviation"] and not s["in"]["speed_agrees"][0]
    assert s["out"]["candidates"][0]["confirm"] == 0
    # G18: the episode keeps a margin above the current section's
    s = last["G18"]
    assert s["out"]["mode"] == "COMPENSATING" and s["out"]["margin_mm"] > s["in"]["section"]["margin_mm"]
    # G24: a TG failure in TG odometry stops the train
    assert last["G24"]["out"]["stop_reason"] == "TG_FAILURE" and not last["G24"]["in"]["tg_ok"]
