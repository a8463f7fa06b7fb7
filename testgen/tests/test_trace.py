"""Traceability checker: links are collected from models, results, C++ and proofs;
dangling references, failed verification and unverified requirements fail with exit 1
and a 'file: entry: reason' line."""
from __future__ import annotations

import json
import shutil

import pytest

from conftest import REPO, edit, fails_with


@pytest.fixture
def trace(cli):
    """trace(root, *extra) runs the trace command on a fixture repository."""

    def run(root, *extra, results=None):
        out = root / "out" / "trace.json"
        r = cli("trace", "--spec", root / "spec", "--src", root,
                "--results", results or root / "results", "--out", out, *extra)
        r.trace = json.loads(out.read_text(encoding="utf-8")) if out.exists() else None
        return r

    return run


def _req(r, rid):
    return next(x for x in r.trace["requirements"] if x["id"] == rid)


def test_valid_tree_passes_with_all_links(tree, trace):
    r = trace(tree())
    assert r.rc == 0, r.err
    t = r.trace
    assert t["schema"] == "railproof/trace/1"
    assert t["errors"] == [] and t["warnings"] == []
    assert [x["id"] for x in t["requirements"]] == ["REQ-MB-001", "REQ-TG-001", "REQ-TG-002",
                                                    "REQ-TG-003", "REQ-TG-004"]
    assert all(x["status"] == "ok" and x["problems"] == [] for x in t["requirements"])
    tg1 = _req(r, "REQ-TG-001")
    assert tg1["links"]["model"] == [{"model": "models/demo.pml",
                                      "property": "REQ_TG_001_repetition",
                                      "verdict": "verified"}]
    assert tg1["links"]["goals"] == ["G1", "G2"]
    assert tg1["links"]["vectors"] == ["TG-RW-001", "TG-TRAP-001"]
    assert tg1["links"]["unit"] == [{"file": "cpp/runtime/demo/tests/demo_test.cpp",
                                     "test": "Sequence.RejectsRepetition"}]
    assert tg1["links"]["code"] == [{"file": "cpp/runtime/demo/src/demo.cpp",
                                     "unit": "CheckSequenceNumber"}]
    tg2 = _req(r, "REQ-TG-002")
    assert tg2["links"]["analysis"] == ["analysis/residual_error.json"]
    assert {c["unit"] for c in tg2["links"]["code"]} == {"Crc16"}
    mb1 = _req(r, "REQ-MB-001")
    assert mb1["links"]["proof"] == [{"file": "proofs/mb/stop_limit.smt2",
                                      "obligation": "stop_limit_behind_rear"}]
    assert mb1["links"]["code"] == [{"file": "cpp/runtime/demo/include/railproof/demo/demo.hpp",
                                     "unit": "StopLimit"}]
    assert mb1["links"]["unit"] == [{"file": "cpp/runtime/demo/tests/demo_test.cpp",
                                     "test": "Crc.KnownValue"}]
    # SIL 4 verified by analysis alone needs no code unit
    assert _req(r, "REQ-TG-004")["links"]["code"] == []
    goals = {g["goal"]: g for g in t["goals"]}
    assert goals["G2"]["status"] == "unreachable" and goals["G2"]["justification"] == "UR-TG-001"
    s = t["summary"]
    assert (s["requirements"], s["ok"], s["error"], s["sil4"]) == (5, 5, 0, 4)
    assert s["properties"] == {"verified": 1, "violated": 0, "incomplete": 0, "missing": 0}
    assert s["mutants"] == {"rejected": 1, "survived": 0, "missing": 0}
    assert s["goals"] == {"labelled": 2, "reached": 1, "unreachable": 1, "missing": 0}
    assert s["vectors"] == 2 and s["unit_tests"] == 2 and s["proof_obligations"] == 1


def test_output_is_deterministic_and_location_independent(tree, trace, tmp_path):
    root = tree()
    first = trace(root)
    text1 = (root / "out/trace.json").read_bytes()
    moved = tmp_path / "elsewhere" / "checkout"
    shutil.copytree(root, moved)
    (moved / "out/trace.json").unlink()
    second = trace(moved)
    assert first.rc == second.rc == 0
    assert (moved / "out/trace.json").read_bytes() == text1
    assert str(tmp_path).encode() not in text1


@pytest.mark.parametrize("case, file, entry, fragment, rid", [
    ("dangling_verifies", "cpp/runtime/demo/tests/extra_test.cpp", "@verifies (line 3)",
     "dangling reference: unknown requirement REQ-TG-099", None),
    ("sil4_no_code", "spec/requirements/tg.yaml", "REQ-TG-001",
     "SIL-4 runtime requirement has no @implements unit under cpp/runtime", "REQ-TG-001"),
    ("sil4_unverified", "spec/requirements/tg.yaml", "REQ-TG-001",
     "verification 'unit': no @verifies test", "REQ-TG-001"),
    ("violated_property", "spin/demo.json", "property REQ_TG_001_repetition",
     "property violated", "REQ-TG-001"),
    ("mutant_survived", "spin/demo.json", "mutant MUTANT_NO_REPEAT_CHECK",
     "mutant survived", "REQ-TG-001"),
    ("unjustified_unreachable", "vectors/demo.coverage.json", "goal G2",
     "unreachable goal without a justification", "REQ-TG-001"),
    ("empty_vectors", "vectors/demo.jsonl", "-", "empty vector set", None),
])
def test_trace_error_classes(tree, trace, case, file, entry, fragment, rid):
    r = trace(tree(case))
    assert r.rc == 1
    assert r.has(file, entry, fragment), r.err
    line = next(ln for ln in r.lines if fragment in ln)
    assert line in r.trace["errors"]
    if rid:
        req = _req(r, rid)
        assert req["status"] == "error"
        assert any(fragment in p for p in req["problems"])


def test_violated_property_also_leaves_model_verification_unmet(tree, trace):
    r = trace(tree("violated_property"))
    assert r.has("spec/requirements/tg.yaml", "REQ-TG-001",
                 "verification 'model': no property naming it is verified")
    assert r.trace["summary"]["properties"]["violated"] == 1


def test_empty_vectors_leave_coverage_dangling(tree, trace):
    r = trace(tree("empty_vectors"))
    assert r.has("vectors/demo.coverage.json", "goal G1",
                 "dangling reference: vector TG-TRAP-001")
    assert r.has("spec/requirements/tg.yaml", "REQ-TG-001",
                 "verification 'vectors': no vector names it")


@pytest.mark.parametrize("file, old, new, efile, entry, fragment", [
    # model annotations
    ("models/demo.pml", "@property REQ_TG_001_repetition REQ-TG-001 :",
     "@property REQ_TG_001_repetition REQ-TG-001 REQ-TG-077 :", "models/demo.pml",
     "@property REQ_TG_001_repetition (line 8)", "unknown requirement REQ-TG-077"),
    ("models/demo.pml", "@goal 2 REQ-TG-001 :", "@goal 2 REQ-TG-1 :", "models/demo.pml",
     "@goal G2 (line 7)", "malformed requirement id 'REQ-TG-1'"),
    ("models/demo.pml", "violates REQ_TG_001_repetition", "violates REQ_TG_999_nothing",
     "models/demo.pml", "@mutant MUTANT_NO_REPEAT_CHECK (line 10)",
     "no @property named REQ_TG_999_nothing"),
    ("models/demo.pml", "// @goal 1 REQ-TG-001 : receiver rejects a repetition\n", "",
     "vectors/demo.coverage.json", "goal G1", "no @goal annotation"),
    # model-checking results
    ("results/spin/demo.json", '"verdict": "verified"', '"verdict": "incomplete"',
     "spin/demo.json", "property REQ_TG_001_repetition", "property incomplete"),
    ("results/spin/demo.json", '"requirements": ["REQ-TG-001"]',
     '"requirements": ["REQ-TG-001", "REQ-TG-088"]', "spin/demo.json",
     "property REQ_TG_001_repetition", "unknown requirement REQ-TG-088"),
    ("results/spin/demo.json", '"name": "MUTANT_NO_REPEAT_CHECK"', '"name": "MUTANT_OTHER"',
     "models/demo.pml", "@mutant MUTANT_NO_REPEAT_CHECK", "mutant has no model-checking result"),
    ("results/spin/demo.json", '"name": "REQ_TG_001_repetition"', '"name": "REQ_TG_001_old"',
     "models/demo.pml", "@property REQ_TG_001_repetition", "has no model-checking result"),
    ("results/spin/demo.json", '"model": "models/demo.pml"', '"model": "models/gone.pml"',
     "spin/demo.json", "model", "model models/gone.pml not found"),
    # vectors and coverage
    ("results/vectors/demo.jsonl", '"requirements": ["REQ-TG-001"], "goal": null',
     '"requirements": ["REQ-TG-055"], "goal": null', "vectors/demo.jsonl", "TG-RW-001",
     "unknown requirement REQ-TG-055"),
    ("results/vectors/demo.jsonl", '"id": "TG-RW-001"', '"id": "TG-TRAP-001"',
     "vectors/demo.jsonl", "TG-TRAP-001", "duplicate vector id"),
    ("results/vectors/demo.jsonl", '{"kind": "header", ', '{"kind": "vector", ',
     "vectors/demo.jsonl", "line 1", "first line must be the header"),
    ("results/vectors/demo.coverage.json", '"justification": "UR-TG-001"',
     '"justification": "UR-TG-009"', "vectors/demo.coverage.json", "goal G2",
     "dangling reference: justification UR-TG-009"),
    ("spec/justifications/tg.yaml", "goal: G2", "goal: G1",
     "vectors/demo.coverage.json", "goal G2", "justification UR-TG-001 is for goal G1"),
    ("spec/justifications/tg.yaml", "model: models/demo.pml", "model: models/other.pml",
     "spec/justifications/tg.yaml", "UR-TG-001", "model models/other.pml not found"),
    ("results/vectors/demo.coverage.json", '"reached": 1', '"reached": 2',
     "vectors/demo.coverage.json", "reached", "says 2 but 1 goals are reached"),
    # C++ and proofs
    ("cpp/runtime/demo/src/demo.cpp", "// @implements REQ-TG-002", "// @implements REQ-TG-2",
     "cpp/runtime/demo/src/demo.cpp", "@implements (line 10)", "malformed requirement id 'REQ-TG-2'"),
    ("cpp/runtime/demo/include/railproof/demo/demo.hpp", "// @implements REQ-MB-001",
     "// @implements REQ-BR-001", "cpp/runtime/demo/include/railproof/demo/demo.hpp",
     "@implements (line 4)", "unknown requirement REQ-BR-001"),
    ("cpp/runtime/demo/src/demo.cpp", "// @implements REQ-TG-001", "// @implements",
     "cpp/runtime/demo/src/demo.cpp", "@implements (line 5)", "tag names no requirement"),
    ("proofs/mb/stop_limit.smt2", "REQ-MB-001 :", "REQ-MB-007 :", "proofs/mb/stop_limit.smt2",
     "@obligation stop_limit_behind_rear (line 1)", "unknown requirement REQ-MB-007"),
    # analysis results
    ("results/analysis/residual_error.json", '"REQ-TG-004"]', '"REQ-TG-044"]',
     "analysis/residual_error.json", "requirements", "unknown requirement REQ-TG-044"),
    ("results/analysis/residual_error.json", '"verdict": "pass"', '"verdict": "fail"',
     "analysis/residual_error.json", "verdict", "analysis result failed"),
])
def test_dangling_and_inconsistent_links(tree, trace, file, old, new, efile, entry, fragment):
    fails_with(trace(tree(edits=[(file, old, new)])), (efile, entry, fragment))


@pytest.mark.parametrize("file, old, new, rid, fragment", [
    ("results/analysis/residual_error.json", '"REQ-TG-002", "REQ-TG-004"', '"REQ-TG-002"',
     "REQ-TG-004", "verification 'analysis': no analysis result names it"),
    ("proofs/mb/stop_limit.smt2", "; @obligation", "; obligation", "REQ-MB-001",
     "verification 'proof': no proof obligation names it"),
])
def test_missing_link_kind(tree, trace, file, old, new, rid, fragment):
    """The requirement rid (in spec/requirements/<its area>.yaml) lacks a kind of link."""
    r = trace(tree(edits=[(file, old, new)]))
    fails_with(r, (f"spec/requirements/{rid[4:6].lower()}.yaml", rid, fragment))
    assert _req(r, rid)["status"] == "error"


def test_extra_links_never_hurt(tree, trace):
    root = tree()
    edit(root / "results/vectors/demo.jsonl", '["REQ-TG-001"], "goal": null',
          '["REQ-TG-001", "REQ-TG-003"], "goal": null')
    r = trace(root)
    assert r.rc == 0, r.err
    assert _req(r, "REQ-TG-003")["links"]["vectors"] == ["TG-RW-001"]


def test_requirement_without_any_vector(tree, trace):
    root = tree()
    vec = root / "results/vectors/demo.jsonl"
    vec.write_text(vec.read_text(encoding="utf-8").replace('"REQ-TG-001"', '"REQ-TG-002"'),
                   encoding="utf-8")
    cov = root / "results/vectors/demo.coverage.json"
    cov.write_text(cov.read_text(encoding="utf-8").replace('"REQ-TG-001"', '"REQ-TG-002"'),
                   encoding="utf-8")
    r = trace(root)
    assert r.rc == 1
    assert r.has("spec/requirements/tg.yaml", "REQ-TG-001",
                 "verification 'vectors': no vector names it")
    # coverage and @goal annotations disagree about the goal's requirements
    assert r.has("vectors/demo.coverage.json", "goal G1", "differ from the @goal annotation")


def test_missing_results_fail_without_flag(tree, trace):
    root = tree()
    shutil.rmtree(root / "results")
    r = trace(root)
    assert r.rc == 1
    assert r.has("results/spin", "-", "no model-checking results")
    assert r.has("results/vectors", "-", "empty or missing vector set")
    assert r.has("results/analysis", "-", "no analysis results")


def test_missing_results_are_warnings_with_flag(tree, trace):
    root = tree()
    shutil.rmtree(root / "results")
    r = trace(root, "--allow-missing-results")
    assert r.rc == 0, r.err
    assert r.warned("results/spin", "-", "allowed by --allow-missing-results")
    assert r.warned("spec/requirements/tg.yaml", "REQ-TG-001",
                    "not yet verified (model-checking results missing)")
    tg1 = _req(r, "REQ-TG-001")
    assert tg1["status"] == "ok"
    assert tg1["links"]["model"][0]["verdict"] == "missing"


def test_flag_does_not_hide_source_problems_or_bad_results(tree, trace):
    root = tree("sil4_no_code")
    shutil.rmtree(root / "results" / "vectors")
    r = trace(root, "--allow-missing-results")
    assert r.rc == 1
    assert r.has("spec/requirements/tg.yaml", "REQ-TG-001", "SIL-4 runtime requirement has no")
    root = tree("violated_property")
    r = trace(root, "--allow-missing-results")
    assert r.rc == 1 and r.has("spin/demo.json", "property REQ_TG_001_repetition", "violated")


def test_flag_still_requires_a_property_annotation(tree, trace):
    root = tree()
    shutil.rmtree(root / "results")
    edit(root / "models/demo.pml",
          "// @property REQ_TG_001_repetition REQ-TG-001 : no telegram is accepted twice\n", "")
    edit(root / "models/demo.pml", "violates REQ_TG_001_repetition", "violates gone")
    r = trace(root, "--allow-missing-results")
    assert r.rc == 1
    assert r.has("spec/requirements/tg.yaml", "REQ-TG-001",
                 "verification 'model': no @property in models/ names this requirement")


def test_invalid_spec_stops_before_tracing(tree, trace):
    r = trace(tree("unknown_hazard"))
    assert r.rc == 1
    assert r.trace is None
    assert r.has("requirements/mb.yaml", "REQ-MB-001", "unknown hazard HAZ-009")


def test_tags_in_prose_and_doc_examples_are_not_links(tree, trace):
    root = tree()
    # demo.cpp mentions "@implements" in prose and demo.pml shows the annotation syntax in
    # a block comment; neither is a tag, so the valid tree has no error or warning
    r = trace(root)
    assert r.rc == 0 and r.trace["warnings"] == []


def test_disabled_test_does_not_count(tree, trace):
    root = tree()
    edit(root / "cpp/runtime/demo/tests/demo_test.cpp", "TEST(Sequence, RejectsRepetition)",
          "TEST(Sequence, DISABLED_RejectsRepetition)")
    r = trace(root)
    assert r.rc == 1
    assert r.warned("demo_test.cpp", "@verifies (line 4)", "is disabled")
    assert r.has("spec/requirements/tg.yaml", "REQ-TG-001", "verification 'unit'")


def test_all_trace_errors_are_collected(tree, trace):
    root = tree("dangling_verifies", "mutant_survived", "unjustified_unreachable",
                "sil4_no_code")
    r = trace(root)
    assert r.rc == 1
    for file, entry, fragment in [
            ("extra_test.cpp", "@verifies", "REQ-TG-099"),
            ("spin/demo.json", "mutant MUTANT_NO_REPEAT_CHECK", "survived"),
            ("vectors/demo.coverage.json", "goal G2", "without a justification"),
            ("spec/requirements/tg.yaml", "REQ-TG-001", "SIL-4")]:
        assert r.has(file, entry, fragment), (file, r.err)
    assert r.trace["summary"]["errors"] == len(r.trace["errors"]) >= 4


def test_real_repository_before_the_pipeline(tmp_path, cli):
    """The real tree parses: every tag and annotation names an existing requirement
    (the verification gaps of work in progress are not asserted here)."""
    out = tmp_path / "trace.json"
    r = cli("trace", "--spec", REPO / "spec", "--src", REPO, "--results", tmp_path / "none",
            "--out", out, "--allow-missing-results")
    t = json.loads(out.read_text(encoding="utf-8"))
    assert not [e for e in t["errors"] if "dangling" in e or "malformed" in e], r.err
    assert t["summary"]["requirements"] >= 19


def test_results_of_another_model_version_are_flagged(tree, trace):
    root = tree()
    with (root / "models/demo.pml").open("a", encoding="utf-8") as fh:
        fh.write("/* edited after the results were produced */\n")
    r = trace(root)
    assert r.rc == 0
    assert r.warned("spin/demo.json", "model_sha256", "differs from models/demo.pml")
    assert r.warned("vectors/demo.jsonl", "model_sha256", "differs from models/demo.pml")


def test_analysis_case_missing_its_target_fails(tree, trace):
    root = tree()
    (root / "results/analysis/residual_error.json").write_text(json.dumps({
        "requirements": ["REQ-TG-002", "REQ-TG-004"],
        "cases": [{"ber": 1e-4, "meets_target": True}, {"ber": 1e-3, "meets_target": False}]}),
        encoding="utf-8")
    r = trace(root)
    assert r.rc == 1
    assert r.has("analysis/residual_error.json", "cases[1]", "target not met")
    assert _req(r, "REQ-TG-004")["status"] == "error"


def test_offline_code_never_implements_a_runtime_requirement(tree, trace):
    """An @implements under cpp/offline is a tool link, never the code of a runtime
    requirement: the SIL-4 requirement REQ-TG-001 stays unimplemented and the error names the
    offline file."""
    root = tree("sil4_no_code")
    tool = root / "cpp/offline/demo/src/demo_study.cpp"
    tool.parent.mkdir(parents=True)
    tool.write_text("// @implements REQ-TG-001\nint DemoStudy() { return 1; }\n", encoding="utf-8")
    r = trace(root)
    assert r.rc == 1
    assert r.has("spec/requirements/tg.yaml", "REQ-TG-001",
                 "SIL-4 runtime requirement has no @implements unit under cpp/runtime (offline code "
                 "never implements a runtime requirement: cpp/offline/demo/src/demo_study.cpp)")
    data = json.loads((root / "out" / "trace.json").read_text(encoding="utf-8"))
    tg1 = next(x for x in data["requirements"] if x["id"] == "REQ-TG-001")
    assert tg1["links"]["code"] == []
    assert tg1["links"]["tool"] == [{"file": "cpp/offline/demo/src/demo_study.cpp", "unit": "DemoStudy"}]


def test_offline_requirement_needs_an_offline_tool(tree, trace):
    """implemented_by: offline exempts a requirement from runtime code only if an offline tool
    implements it; runtime code does not count for it either."""
    root = tree()
    edit(root / "spec/requirements/tg.yaml", "id: REQ-TG-002\n", "id: REQ-TG-002\n    implemented_by: offline\n")
    r = trace(root)
    assert r.rc == 1
    assert r.has("spec/requirements/tg.yaml", "REQ-TG-002",
                 "implemented_by offline: no @implements unit under cpp/offline names it")
    tool = root / "cpp/offline/demo/tools/check_data.cpp"
    tool.parent.mkdir(parents=True)
    tool.write_text("// @implements REQ-TG-002\nint CheckData() { return 0; }\n", encoding="utf-8")
    r = trace(root)
    assert r.rc == 0, r.err


def test_every_requirement_belongs_to_a_registered_capability(tree, trace):
    """The trace names each requirement's capability (spec/capabilities.yaml); an area of no
    capability, or no registry at all, is an error."""
    root = tree()
    r = trace(root)
    assert r.rc == 0, r.err
    data = json.loads((root / "out" / "trace.json").read_text(encoding="utf-8"))
    assert {x["id"]: x["capability"] for x in data["requirements"]}["REQ-MB-001"] == "mb"
    edit(root / "spec/capabilities.yaml", "    areas: [MB]\n", "    areas: [BR]\n")
    edit(root / "spec/capabilities.yaml", "  - name: mb\n", "  - name: br\n")
    r = trace(root)
    assert r.rc == 1
    assert r.has("spec/requirements/mb.yaml", "REQ-MB-001", "area MB belongs to no capability of")
    (root / "spec/capabilities.yaml").unlink()
    r = trace(root)
    assert r.rc == 1 and "capabilities.yaml: -: file not found" in r.err
