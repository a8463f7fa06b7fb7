"""Tests of the telegram layer's part of vector generation (railproof_testgen.capabilities.tg,
models/tg.pml, spec/schemas/vectors_tg.schema.json): parser, conversion per endpoint role, ids
and header on hand-made model output; the vectors of a build (RAILPROOF_RESULTS_DIR) against the
design note. The C++ conformance runner is the behavioural check of the vectors."""
from pathlib import Path

import pytest

from railproof_testgen import spin
from railproof_testgen.capabilities.tg import PART
from railproof_testgen.errors import PipelineError
from railproof_testgen.vectors import Target
from vector_results import vector_set

REPO = Path(__file__).resolve().parents[2]
MODEL = REPO / "models" / "tg.pml"
BOUNDS = {"tick_ms": 1500, "seq_modulus": 9, "seq_window": 4, "narrow_seq_window": 2, "history_depth": 4,
          "turnaround_ticks": 2, "link_ticks": 2, "echo_ticks": 2, "init_own_seq": 7, "init_peer_seq": 6,
          "ground_id": 1, "train_id": 42, "other_train_id": 43}


def test_annotations_of_the_telegram_model():
    ann = spin.parse_annotations(MODEL)
    names = {p.name for p in ann.properties}
    assert "REQ_TG_009_turnaround" in names
    assert all(p.requirements for p in ann.properties)
    assert len(ann.goals) == 20 and [g.number for g in ann.goals] == list(range(20))
    assert {m.name for m in ann.mutants} >= {"MUTANT_SEQ_WIDTH_8", "MUTANT_NO_AUTH_CHECK"}
    assert "R_GUARANTEE_ECHO_AGE" in ann.asserts
    healthy = [p for p in ann.properties if p.config == "HEALTHY"]
    assert [p.name for p in healthy] == ["REQ_TG_016_availability"]
    assert [v.define for v in ann.variants] == ["VARIANT_NARROW_WINDOW"]


RUN = "\n".join([
    "  @IN tick", "  @OUT tx seq=7 echo=255 link=0 eb=1 abnormal=1",
    "  @IN rx seq=6 echo=7 mode=4", "  @OUT rx verdict=2 gap=0 link=0 eb=1 abnormal=1",
    "  @IN rx seq=6 echo=7 mode=0", "  @OUT rx verdict=0 gap=0 link=1 eb=0 abnormal=0",
    "  @IN tick"])  # an input cut off by the end of a trail is dropped


def test_parse_events_and_steps_for_both_roles():
    ev = PART.parse_events(RUN)
    assert len(ev) == 3
    g = PART.to_steps(ev, BOUNDS, None, "ground")
    t = PART.to_steps(ev, BOUNDS, None, "train")
    assert g[0]["out"] == {"tx": {"seq": 7, "echo": None}, "link": "NONE", "tracking": "ABNORMAL"}
    assert t[0]["out"] == {"tx": {"seq": 7, "echo": None}, "link": "NONE", "eb": True}
    # misaddressed: from another train towards the ground, towards another train from the ground
    assert g[1]["in"]["tg"]["src"] == 43 and g[1]["in"]["tg"]["type"] == "POSITION"
    assert t[1]["in"]["tg"]["dst"] == 43 and t[1]["in"]["tg"]["type"] == "CONTROL"
    assert g[1]["out"]["verdict"] == "REJ_ADDRESS"
    assert t[2]["out"] == {"verdict": "ACCEPT", "gap": 0, "link": "UP", "eb": False}
    assert PART.observed_requirements(ev) == {"REQ-TG-003", "REQ-TG-008"}


def test_output_without_input_is_an_error():
    with pytest.raises(PipelineError, match="without @IN"):
        PART.parse_events("@OUT rx verdict=0 gap=0 link=1 eb=0 abnormal=0")


def _target():
    return Target(MODEL, spin.parse_annotations(MODEL), BOUNDS, "test")


def test_one_run_gives_a_vector_per_role_with_ids_of_the_configuration():
    vecs = PART.vectors(_target(), None, PART.parse_events(RUN), PART.vector_id("trap", None, "G5"), "trap", "G5",
                        None, ["REQ-TG-003"])
    assert [(v["id"], v["role"]) for v in vecs] == [("TG-TRAP-G5-ground", "ground"), ("TG-TRAP-G5-train", "train")]
    assert all(v["requirements"] == ["REQ-TG-003", "REQ-TG-008"] for v in vecs)
    assert PART.vector_id("boundary", "VARIANT_NARROW_WINDOW", "G12") == "TG-BOUNDARY-G12narrowwindow"
    assert PART.vector_id("random", "HEALTHY", "S3") == "TG-RANDOM-HEALTHYS3"
    assert PART.vector_id("random", None, "S3") == "TG-RANDOM-S3"


def test_header_of_the_variant_overrides_its_parameter():
    main, narrow = PART.header(_target(), None), PART.header(_target(), "VARIANT_NARROW_WINDOW")
    assert main["parameters"]["seq_window"] == 4 and "variant" not in main
    assert narrow["parameters"]["seq_window"] == 2 and narrow["variant"] == "VARIANT_NARROW_WINDOW"
    assert main["parameters"]["turnaround_ms"] == 3000 and main["unit_scales"] == {"time_ms_per_tick": 1500}
    assert {k: v for k, v in narrow["parameters"].items() if k != "seq_window"} == \
        {k: v for k, v in main["parameters"].items() if k != "seq_window"}


# ---- the build's vectors -------------------------------------------------------------------------
def test_every_run_is_a_vector_pair_of_the_two_roles():
    vs = vector_set("tg")
    for name in vs.files:
        vecs = vs.vectors(name)
        runs = {}
        for v in vecs:
            stem, role = v["id"].rsplit("-", 1)
            assert role == v["role"] and role in ("ground", "train")
            runs.setdefault(stem, []).append(v)
        for stem, pair in runs.items():
            assert sorted(v["role"] for v in pair) == ["ground", "train"], stem
            g, t = sorted(pair, key=lambda v: v["role"])
            assert len(g["steps"]) == len(t["steps"]) and g["requirements"] == t["requirements"]
            for sg, st in zip(g["steps"], t["steps"]):  # the same run: same sequence numbers and verdicts
                assert sg["in"]["ev"] == st["in"]["ev"] and sg["out"].get("verdict") == st["out"].get("verdict")
                assert sg["out"]["link"] == st["out"]["link"]


def test_the_window_edge_is_reached_in_the_narrow_variant():
    vs = vector_set("tg")
    goals = {g["id"]: g for g in vs.coverage["goals"]}
    assert goals["G12"]["status"] == "unreachable" and goals["G12"]["variant"] == "VARIANT_NARROW_WINDOW"
    header = vs.header("tg.variant_narrow_window.jsonl")
    assert header["variant"] == "VARIANT_NARROW_WINDOW"
    assert header["parameters"]["seq_window"] < vs.header("tg.jsonl")["parameters"]["seq_window"]
    g12 = vs.by_goal("tg.variant_narrow_window.jsonl")["G12"]
    assert g12["kind"] == "boundary" and g12["steps"][-1]["out"]["verdict"] == "REJ_SEQUENCE"


def test_the_healthy_walks_evidence_the_availability():
    vs = vector_set("tg")
    healthy = [v for v in vs.vectors("tg.jsonl") if v["id"].startswith("TG-RANDOM-HEALTHY")]
    assert healthy and all("REQ-TG-016" in v["requirements"] for v in healthy)
    for v in healthy:  # a perfect channel: the link is up from the third tick on (REQ-TG-016)
        ticks = [s for s in v["steps"] if s["in"]["ev"] == "tick"]
        assert all(s["out"]["link"] == "UP" for s in ticks[2:]), v["id"]
