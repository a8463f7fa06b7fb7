"""Tests of the braking part of vector generation: the speed-supervision decision
(railproof_testgen.capabilities.br, models/br.pml, spec/schemas/vectors_br.schema.json). The
C++ conformance runner (railproof_conformance_br) is the behavioural check of the vectors; these
tests check the parser and conversion on hand-made model output, and that the vectors of a build
(RAILPROOF_RESULTS_DIR) are physically consistent and hit every boundary."""
from pathlib import Path

import pytest

from railproof_testgen import spin
from railproof_testgen.capabilities import br
from railproof_testgen.capabilities.br import PART
from railproof_testgen.errors import PipelineError
from railproof_testgen.vectors import Target
from vector_results import vector_set

REPO = Path(__file__).resolve().parents[2]
MODEL = REPO / "models" / "br.pml"

# the seeded C++ decision faults of cpp/runtime/br/src/supervisor.cpp, each mirrored by a mutant
CPP_FAULTS = ["RESET_IGNORES_HANDLE", "RELEASE_WHILE_MOVING", "NO_RELEASE_LEAD", "EMERGENCY_LATE",
              "EMERGENCY_NOT_LATCHED"]


def test_annotations_of_the_braking_model():
    ann = spin.parse_annotations(MODEL)
    props = {p.name: p for p in ann.properties}
    assert set(props) == {"REQ_BR_001_emergency", "REQ_BR_006_latch", "REQ_BR_002_service",
                          "REQ_BR_003_levels", "REQ_BR_003_release", "REQ_BR_003_indication"}
    for name, p in props.items():  # named by the requirement it verifies
        assert name[:10].replace("_", "-") in p.requirements
        assert p.config is None
    covered = {r for p in ann.properties for r in p.requirements}
    assert covered == {"REQ-BR-001", "REQ-BR-002", "REQ-BR-003", "REQ-BR-006"}
    mutants = {m.name for m in ann.mutants}
    assert {f"MUTANT_{f}" for f in CPP_FAULTS} <= mutants
    assert all(m.violates in props for m in ann.mutants)
    assert [g.number for g in ann.goals] == list(range(len(ann.goals)))
    assert all(g.requirements and g.label for g in ann.goals)


def _cycle(vs, st, he, rs, pats, level, appr, latched):
    lines = [f"  @IN cycle vs={vs} st={st} he={he} rs={rs}"]
    lines += [f"  @IN p{k}={v}" for k, v in enumerate(pats)]
    lines.append(f"  @OUT level={level} appr={appr} latched={latched}")
    return lines


def test_parse_events_and_steps():
    text = "\n".join(
        _cycle(3, 0, 0, 0, [2, 1, 1, 1, 1, 0], 5, 1, 1)
        + _cycle(0, 1, 1, 1, [0, 0, 0, 0, 0, 0], 0, 0, 0)
        + ["  @IN cycle vs=1 st=0 he=0 rs=0", "  @IN p0=1"])  # cut off by the end of a trail
    ev = PART.parse_events(text)
    assert len(ev) == 2
    steps = PART.to_steps(ev, {}, None)
    assert steps[0] == {
        "in": {"v_s": 3, "v_e": 2, "v_7n": 1, "v_6n": 1, "v_5n": 1, "v_4n": 1, "v_release": 0,
               "standstill": False, "handle_emergency": False, "reset": False},
        "out": {"level": "EB", "pattern_approaching": True, "emergency_latched": True}}
    assert steps[1]["in"]["standstill"] and steps[1]["out"]["level"] == "NONE"
    assert PART.observed_requirements(steps) == {"REQ-BR-001", "REQ-BR-003", "REQ-BR-006"}


def test_output_without_complete_inputs_is_an_error():
    with pytest.raises(PipelineError, match="without a complete @IN cycle"):
        PART.parse_events("@IN cycle vs=1 st=0 he=0 rs=0\n@IN p0=1\n@OUT level=0 appr=0 latched=0")
    with pytest.raises(PipelineError, match="unrecognised"):
        PART.parse_events("@OUT tx seq=1")


def test_header_records_units_and_bounds():
    h = PART.header(Target(MODEL, spin.parse_annotations(MODEL), {"vmax": 9, "cycles": 6}, "test"), None)
    assert h["configuration"] == "default" and h["units"] == br.UNITS == "abstract speed units = mm/s"
    assert h["parameters"] == {"model_vmax": 9, "model_cycles": 6, "levels": br.LEVELS}
    assert h["model"] == "models/br.pml" and h["model_sha256"] == spin.sha256_file(MODEL)


def test_vectors_are_consistent_and_hit_every_boundary():
    vs = vector_set("br")
    vecs = vs.vectors("br.jsonl")
    assert set(vs.files) == {"br.jsonl", "br.unit.jsonl"}
    assert vs.coverage["reached"] == vs.coverage["labelled"]  # every branch
    vmax = vs.header("br.jsonl")["parameters"]["model_vmax"]
    cycles = vs.header("br.jsonl")["parameters"]["model_cycles"]
    assert all(len(v["steps"]) == cycles for v in vecs if v["kind"] == "random")
    steps = [s for v in vecs for s in v["steps"]]
    for s in steps:
        i = s["in"]
        assert all(0 <= i[k] <= vmax for k in ("v_s", *br.PATTERNS))
        assert not i["standstill"] or i["v_s"] == 0  # standstill implies v_s = 0
        assert s["out"]["level"] != "EB" or s["out"]["emergency_latched"]
    for p in br.PATTERNS:  # v_s exactly at and one above every pattern speed
        assert any(s["in"]["v_s"] == s["in"][p] and s["in"]["v_s"] > 0 for s in steps), p
        assert any(s["in"]["v_s"] == s["in"][p] + 1 for s in steps), p
    # the emergency boundary vector: EB at v_e + 1 in a cycle without a latch
    g5 = vs.by_goal("br.jsonl")["G5"]
    last = g5["steps"][-1]
    assert last["in"]["v_s"] == last["in"]["v_e"] + 1 and last["out"]["level"] == "EB"
    # every latch-release condition is missing alone in some vector, with the EB held
    held = [s["in"] for v in vecs if v["goal"] in ("G0", "G1", "G2") for s in v["steps"][-1:]]
    assert sorted((i["standstill"], i["handle_emergency"], i["reset"]) for i in held) == [
        (False, True, True), (True, False, True), (True, True, False)]


def _exceeded(i):
    return [i["v_s"] > i[p] for p in br.PATTERNS]


def test_unit_vectors_stay_in_the_units_environment():
    """br.unit.jsonl (variant REALISABLE): in every step v_e is exceeded only with v_7n, and the
    service points v_s does not exceed are one contiguous run (the rest a prefix and a suffix);
    every goal but G21 (EB with the service pattern not exceeded) has a vector there."""
    vs = vector_set("br")
    vecs = vs.vectors("br.unit.jsonl")
    assert vs.header("br.unit.jsonl")["configuration"] == "REALISABLE"
    assert all(v["id"].startswith("BR-") and "-UNIT-" in v["id"] for v in vecs)
    for v in vecs:
        for s in v["steps"]:
            e = _exceeded(s["in"])
            assert not e[0] or e[1], (v["id"], s["in"])
            service = "".join("1" if x else "0" for x in e[1:])
            assert "1" not in service.strip("1"), (v["id"], s["in"])  # 1..1 0..0 1..1
    goals = {v["goal"] for v in vecs if v["goal"]}
    assert goals == {f"G{k}" for k in range(24)} - {"G21"}
    assert sum(v["kind"] == "random" for v in vecs) == 50
    # the default file keeps the unordered relations the unit cannot give (module replay only)
    default = [s["in"] for v in vs.vectors("br.jsonl") for s in v["steps"]]
    assert any(e[0] and not e[1] for e in map(_exceeded, default))
