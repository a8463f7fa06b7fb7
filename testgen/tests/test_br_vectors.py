"""Tests of the speed-supervision decision vectors (railproof_testgen.br_vectors,
models/br.pml, spec/schemas/vectors_br.schema.json). The C++ conformance runner
(railproof_conformance_br) is the behavioural check of the vectors; these tests check that
they are generated, schema-valid, physically consistent and cover every goal and boundary."""
import json
import shutil
from pathlib import Path

import jsonschema
import pytest
import yaml

from railproof_testgen import br_vectors, spin, vectors
from railproof_testgen.errors import PipelineError

REPO = Path(__file__).resolve().parents[2]
MODEL = REPO / "models" / "braking.pml"
SCHEMA = REPO / "spec" / "schemas" / "vectors_br.schema.json"
needs_spin = pytest.mark.skipif(shutil.which("spin") is None or shutil.which("cc") is None,
                                reason="spin and a C compiler are needed")

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
    ev = br_vectors.parse_events(text)
    assert len(ev) == 2
    steps = br_vectors.to_steps(ev)
    assert steps[0] == {
        "in": {"v_s": 3, "v_e": 2, "v_7n": 1, "v_6n": 1, "v_5n": 1, "v_4n": 1, "v_release": 0,
               "standstill": False, "handle_emergency": False, "reset": False},
        "out": {"level": "EB", "pattern_approaching": True, "emergency_latched": True}}
    assert steps[1]["in"]["standstill"] and steps[1]["out"]["level"] == "NONE"
    assert br_vectors.observed_requirements(steps) == {"REQ-BR-001", "REQ-BR-003", "REQ-BR-006"}


def test_output_without_complete_inputs_is_an_error():
    with pytest.raises(PipelineError, match="without a complete @IN cycle"):
        br_vectors.parse_events("@IN cycle vs=1 st=0 he=0 rs=0\n@IN p0=1\n@OUT level=0 appr=0 latched=0")
    with pytest.raises(PipelineError, match="unrecognised"):
        br_vectors.parse_events("@OUT tx seq=1")


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    if shutil.which("spin") is None or shutil.which("cc") is None:
        pytest.skip("spin and a C compiler are needed")
    tmp = tmp_path_factory.mktemp("br")
    params = tmp / "params"
    params.mkdir()
    # the model bounds of spec/parameters/br.yaml, as gen-params writes them
    data = yaml.safe_load((REPO / "spec" / "parameters" / "braking.yaml").read_text(encoding="utf-8"))
    (params / "br_params.pml").write_text(
        "".join(f"#define {e['id'].upper()} {e['value']}\n" for e in data["model_bounds"]), encoding="utf-8")
    out = tmp / "vectors"
    cov = vectors.generate(MODEL, params, REPO / "spec", tmp / "work", out, walks=4, jobs=2)
    lines = [json.loads(ln) for ln in (out / "braking.jsonl").read_text(encoding="utf-8").splitlines()]
    return cov, lines, out, spin.read_bounds(params / "br_params.pml")


@needs_spin
def test_vectors_are_schema_valid_and_cover_every_goal(generated):
    cov, lines, out, bounds = generated
    validator = jsonschema.Draft202012Validator(json.loads(SCHEMA.read_text(encoding="utf-8")))
    for n, obj in enumerate(lines, 1):
        assert not list(validator.iter_errors(obj)), f"line {n}"
    header, vecs = lines[0], lines[1:]
    assert header["kind"] == "header" and header["model"] == "models/br.pml"
    assert header["units"] == "abstract speed units = mm/s"
    assert header["model_sha256"] == spin.sha256_file(MODEL)
    ann = spin.parse_annotations(MODEL)
    assert cov["labelled"] == len(ann.goals)
    ids = {v["id"] for v in vecs}
    assert len(ids) == len(vecs)
    for g in cov["goals"]:  # reached with a vector, or justified
        if g["status"] == "reached":
            assert g["vectors"] and set(g["vectors"]) <= ids
        else:
            assert g["justification"], g
    assert cov["reached"] == len(ann.goals)  # every branch of the decision is reachable
    assert sum(v["kind"] == "random" for v in vecs) == 4
    on_disk = json.loads((out / "braking.coverage.json").read_text(encoding="utf-8"))
    assert on_disk["reached"] == cov["reached"]


@needs_spin
def test_vectors_are_consistent_and_hit_every_boundary(generated):
    _cov, lines, _out, bounds = generated
    vmax = bounds["vmax"]
    steps = [s for v in lines[1:] for s in v["steps"]]
    for s in steps:
        i = s["in"]
        assert all(0 <= i[k] <= vmax for k in ("v_s", *br_vectors.PATTERNS))
        assert not i["standstill"] or i["v_s"] == 0  # standstill implies v_s = 0
        assert s["out"]["level"] != "EB" or s["out"]["emergency_latched"]
    for p in br_vectors.PATTERNS:  # v_s exactly at and one above every pattern speed
        assert any(s["in"]["v_s"] == s["in"][p] and s["in"]["v_s"] > 0 for s in steps), p
        assert any(s["in"]["v_s"] == s["in"][p] + 1 for s in steps), p
    # the emergency boundary vector: EB at v_e + 1 in a cycle without a latch
    g5 = next(v for v in lines[1:] if v["goal"] == "G5")
    last = g5["steps"][-1]
    assert last["in"]["v_s"] == last["in"]["v_e"] + 1 and last["out"]["level"] == "EB"
    # every latch-release condition is missing alone in some vector, with the EB held
    held = [s["in"] for v in lines[1:] if v["goal"] in ("G0", "G1", "G2") for s in v["steps"][-1:]]
    assert sorted((i["standstill"], i["handle_emergency"], i["reset"]) for i in held) == [
        (False, True, True), (True, False, True), (True, True, False)]
