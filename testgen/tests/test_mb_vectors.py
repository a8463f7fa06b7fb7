"""Tests of the moving-block part of vector generation (railproof_testgen.capabilities.mb,
models/mb.pml, spec/schemas/vectors_mb.schema.json): the parser and the conversion to mm and ms
(design note §2) on hand-made model output, the header, and the vectors of a build
(RAILPROOF_RESULTS_DIR): each goal's vector in its configuration's file, the walks of the full,
TRIO and FAIR configurations. The C++ conformance runner is the behavioural check of the vectors."""
from pathlib import Path

import pytest

from railproof_testgen import spin, vectors
from railproof_testgen.capabilities.mb import PART
from railproof_testgen.errors import PipelineError
from vector_results import vector_set

REPO = Path(__file__).resolve().parents[2]
MODEL = REPO / "models" / "mb.pml"
BOUNDS = vectors.model_bounds(Path(__file__).parent / "fixtures" / "spin" / "mb_params.pml")

RUN = """spin: unrelated
  @IN report t=0 front=7 ext=0
  @OUT report t=0 tracked=1
  @IN env cmd=1 arg=0
  @OUT env poss=1 side_req=0
  @IN tick
  @OUT train t=1 grant=3 why=2 abn=0 usable=1
  @OUT train t=0 grant=-9 why=7 abn=1 usable=0
  @OUT il main=1 side=0 pts=0 poss=1 occ=96
  @IN deliver t=1 lim=3 age=1
  @OUT ob t=1 verdict=0 lim=3
  @IN deliver t=0 lim=5 age=0
  @OUT ob t=0 verdict=2 lim=5
  @IN tick
"""


def test_parse_events_and_steps():
    ev = PART.parse_events(RUN)
    assert [i["ev"] for i, _o in ev] == ["report", "cmd", "tick", "deliver", "deliver"]  # the last tick is cut off
    steps = PART.to_steps(ev, BOUNDS, None)
    mm, ms = BOUNDS["unit_mm"], BOUNDS["tick_ms"]
    assert steps[0] == {"in": {"ev": "report", "train": 0, "front_mm": 8 * mm, "correction_mm": 0},
                        "out": {"tracked": True}}
    assert steps[1] == {"in": {"ev": "cmd", "cmd": "POSSESSION_REQUEST", "train": None},
                        "out": {"possession": "REQUESTED", "siding_requested": False}}
    tick = steps[2]["out"]
    # trains in train order; an abnormal train without a telegram has no limit
    assert tick["trains"] == [{"limit_mm": None, "kind": "ABNORMAL_TRAIN", "abnormal": True, "authority_usable": False},
                              {"limit_mm": 4 * mm, "kind": "FIXED_BLOCK", "abnormal": False, "authority_usable": True}]
    assert tick["occupied"] == [5, 6] and tick["main_route"] and tick["possession"] == "REQUESTED"
    # an accepted limit is held by the train; a limit refused before any acceptance shows none
    assert steps[3] == {"in": {"ev": "deliver", "train": 1, "limit_mm": 4 * mm, "age_ms": ms},
                        "out": {"verdict": "ACCEPT", "limit_mm": 4 * mm}}
    assert steps[4]["out"] == {"verdict": "NOT_NEWER", "limit_mm": None}
    assert PART.observed_requirements(steps) == {"REQ-MB-001", "REQ-MB-003", "REQ-MB-014", "REQ-MB-010",
                                                 "REQ-MB-024", "REQ-MB-006", "REQ-MB-004", "REQ-MB-009"}


def test_malformed_model_output_is_an_error():
    with pytest.raises(PipelineError, match="without its @IN tick"):
        PART.parse_events("@IN report t=0 front=7 ext=0\n@OUT il main=1 side=0 pts=0 poss=1 occ=0")
    with pytest.raises(PipelineError, match="unrecognised"):
        PART.parse_events("@OUT level=1 appr=0 latched=0")


def _header(config=None):
    return PART.header(vectors.Target(MODEL, spin.parse_annotations(MODEL), BOUNDS, "test"), config)


def test_header_per_configuration():
    full, core, fair = _header(), _header("CORE"), _header("FAIR")
    mm = BOUNDS["unit_mm"]
    assert full["configuration"] == "default" and core["configuration"] == "CORE"
    assert len(full["parameters"]["initial_front_mm"]) == BOUNDS["trains"]
    assert len(core["parameters"]["initial_front_mm"]) == 2
    assert full["parameters"]["blocks_mm"][:2] == [0, BOUNDS["block_units"] * mm]
    assert not full["parameters"]["secured_at_start"] and core["parameters"]["secured_at_start"]
    assert fair["parameters"]["boundary_accepted_at_start"]
    assert full["unit_scales"] == {"time_ms_per_tick": BOUNDS["tick_ms"], "mm_per_unit": mm}


def test_ids_and_order():
    assert PART.vector_id("trap", "CORE", "G3") == "MB-TRAP-G3"  # goal vectors carry no configuration
    assert PART.vector_id("random", "FAIR", "S2") == "MB-RANDOM-FAIRS2"
    walks = [{"id": f"MB-RANDOM-S{k}", "kind": "random"} for k in (1, 2, 10)]
    # the main file by id as text (its established order), the configurations' files as generated
    assert [v["id"] for v in PART.order(None, walks)] == ["MB-RANDOM-S1", "MB-RANDOM-S10", "MB-RANDOM-S2"]
    assert PART.order("TRIO", walks) == walks


# ---- the build's vectors -------------------------------------------------------------------------
def test_each_goal_vector_is_in_its_configuration_file():
    vs = vector_set("mb")
    for g in vs.coverage["goals"]:
        config = PART.configuration(None if g["configuration"] == "default" else g["configuration"])
        name = f"mb{config.suffix}.jsonl"
        assert vs.header(name)["configuration"] == g["configuration"]
        assert set(g["vectors"]) <= {v["id"] for v in vs.vectors(name)}, g["id"]


def test_walks_of_the_full_trio_and_fair_configurations():
    vs = vector_set("mb")
    assert all(v["kind"] == "random" for v in vs.vectors("mb.jsonl"))
    for name, tag in (("mb.trio.jsonl", "TRIO"), ("mb.fair.jsonl", "FAIR")):
        walks = vs.vectors(name)
        assert walks and all(v["id"].startswith(f"MB-RANDOM-{tag}S") for v in walks)
    assert all("REQ-MB-018" in v["requirements"] for v in vs.vectors("mb.fair.jsonl"))
    assert not any("REQ-MB-018" in v["requirements"] for v in vs.vectors("mb.trio.jsonl"))
    trains = vs.header("mb.trio.jsonl")["parameters"]["initial_front_mm"]
    for v in vs.vectors("mb.trio.jsonl"):  # every tick reports every train of the configuration
        assert all(len(s["out"]["trains"]) == len(trains) for s in v["steps"] if s["in"]["ev"] == "tick")
