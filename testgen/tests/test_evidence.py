"""Tests of the evidence command: renders the fixture results with Sphinx + sphinx-needs +
sphinx-test-reports, checks the pages, the manifest, its reproducibility and the errors."""
from __future__ import annotations

import copy
import hashlib
import json
import re
import shutil
from pathlib import Path

import pytest

from railproof_testgen import __main__ as cli
from railproof_testgen import evidence
from railproof_testgen.errors import PipelineError

REPO = Path(__file__).resolve().parents[2]
FIX = Path(__file__).resolve().parent / "fixtures" / "evidence"
SPEC = FIX / "spec"
RESULTS = FIX / "results"
TOOLS = FIX / "tool-versions.json"


def _snapshot(tree: Path) -> dict:
    return {p.relative_to(tree).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(tree.rglob("*")) if p.is_file()}


def _repo_copy(tmp: Path) -> Path:
    """A repository root holding only the evidence sources (no models/, so the model-hash
    check reports 'not in the source tree' rather than comparing with a live model)."""
    root = tmp / "repo"
    shutil.copytree(REPO / "evidence", root / "evidence",
                    ignore=shutil.ignore_patterns("__pycache__"))
    return root


def _results_copy(tmp: Path, name: str = "results") -> Path:
    dest = tmp / name
    shutil.copytree(RESULTS, dest)
    return dest


def _read_json(p: Path):
    return json.loads(p.read_text(encoding="utf-8"))


def _write_json(p: Path, data) -> None:
    p.write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")


def scale_results(dest: Path, n_vectors: int) -> None:
    """Copy the fixture results and grow the vector set to n_vectors: extra random-walk
    vectors (steps of the fixture vectors), one conformance case per vector and the trace
    links to them, as the pipeline would produce for a larger model."""
    shutil.copytree(RESULTS, dest)
    vfile = dest / "vectors" / "telegram.jsonl"
    lines = vfile.read_text(encoding="utf-8").splitlines()
    header, vectors = lines[0], [json.loads(x) for x in lines[1:]]
    base = list(vectors)
    i = 0
    while len(vectors) < n_vectors:
        v = copy.deepcopy(base[i % len(base)])
        v["id"] = f"TG-RW-{1000 + i:04d}"
        v["goal"] = f"random walk seed {1000 + i}"
        vectors.append(v)
        i += 1
    vfile.write_text("\n".join([header] + [json.dumps(v, sort_keys=True) for v in vectors]) + "\n",
                     encoding="utf-8")
    conf = ['<?xml version="1.0" encoding="UTF-8"?>',
            f'<testsuites tests="{len(vectors)}" failures="0" errors="0" name="AllTests">',
            f'  <testsuite name="Conformance/VectorReplay" tests="{len(vectors)}" failures="0" '
            'skipped="0" errors="0" time="0.2">']
    conf += [f'    <testcase name="Replays/{v["id"].replace("-", "_")}" status="run" '
             f'result="completed" time="0" classname="Conformance/VectorReplay" />' for v in vectors]
    conf += ["  </testsuite>", "</testsuites>"]
    (dest / "tests" / "conformance" / "conformance.xml").write_text("\n".join(conf) + "\n",
                                                                   encoding="utf-8")
    trace = _read_json(dest / "trace.json")
    for r in trace["requirements"]:
        r["links"]["vectors"] = [v["id"] for v in vectors if r["id"] in v["requirements"]]
    _write_json(dest / "trace.json", trace)


# ------------------------------------------------------------------------------------------
# helpers (no Sphinx run)


def test_need_id_is_valid_for_sphinx_needs():
    assert evidence.need_id("PROP", "telegram", "REQ_TG_001_repetition") == \
        "PROP_TELEGRAM_REQ_TG_001_REPETITION"
    assert evidence.need_id("TG-TRAP-017") == "TG-TRAP-017"
    assert evidence.need_id("tc", "Conformance/Vector Replay") == "TC_CONFORMANCE_VECTOR_REPLAY"
    assert evidence.need_id("1abc") == "X_1ABC"
    assert evidence.need_id("TC", "Receiver", "Rejects.Repetition", upper=False) == \
        "TC_Receiver_Rejects_Repetition"


def test_rst_escape_and_number_format():
    assert evidence.rst_escape("a*b `c` d_ |e|\nf") == r"a\*b \`c\` d\_ \|e\| f"
    assert evidence.rst_escape("- not a list") == r"\- not a list"
    assert evidence.fmt_value(True) == "yes"
    assert evidence.fmt_value(7200.0) == "7200"
    assert evidence.fmt_value(1.5224465583692029e-61) == "1.522e-61"
    assert evidence.fmt_value(0.00797205593005601) == "0.00797206"
    assert evidence.fmt_value(None) == "n/a"
    assert evidence.fmt_value([1, 2.5]) == "1, 2.5"


def test_step_lines_never_hold_a_dynamic_function_marker():
    line = evidence.safe_json_line({"m": [[1, 2], [3]], "n": {"x": [[[]]]}})
    assert "[[" not in line and "]]" not in line
    assert json.loads(line) == {"m": [[1, 2], [3]], "n": {"x": [[[]]]}}


def test_junit_parser_counts_errors_and_skips(tmp_path):
    xml = tmp_path / "r.xml"
    xml.write_text('<testsuites><testsuite name="S" tests="4">'
                   '<testcase classname="S" name="ok"/>'
                   '<testcase classname="S" name="bad"><failure message="x"/></testcase>'
                   '<testcase classname="S" name="boom"><error message="y"/></testcase>'
                   '<testcase classname="S" name="later"><skipped/></testcase>'
                   '</testsuite></testsuites>', encoding="utf-8")
    jf = evidence._parse_junit(xml, "tests/r.xml")
    assert [c.result for c in jf.suites[0][1]] == ["passed", "failure", "error", "skipped"]
    assert jf.error_elements == 1


def test_unit_test_names_from_trace_match_gtest_and_pytest_cases():
    gt = evidence.JUnitCase("Receiver", "Receiver", "RejectsRepetition", "passed", "0")
    py = evidence.JUnitCase("pytest", "tests.test_params", "test_rejects_duplicate_id", "passed", "0")
    assert evidence._unit_match("Receiver.RejectsRepetition", evidence._case_keys(gt), gt.name)
    assert not evidence._unit_match("Receiver.RejectsOutOfWindow", evidence._case_keys(gt), gt.name)
    assert evidence._unit_match("testgen/tests/test_params.py::test_rejects_duplicate_id",
                                evidence._case_keys(py), py.name)


def test_model_hash_is_compared_with_the_source_tree(tmp_path):
    repo = _repo_copy(tmp_path)
    results = _results_copy(tmp_path)
    model_text = b"/* telegram model as checked */\n"
    (repo / "models").mkdir()
    (repo / "models" / "telegram.pml").write_bytes(model_text)
    spin = _read_json(results / "spin" / "telegram.json")
    spin["model_sha256"] = hashlib.sha256(model_text).hexdigest()
    _write_json(results / "spin" / "telegram.json", spin)
    m = evidence.Model(evidence.load_inputs(SPEC, results, repo, TOOLS), "cmd")
    assert m.models[0]["src_check"] == "matches the source tree"
    assert m.verdict == "PASS", m.problems

    (repo / "models" / "telegram.pml").write_bytes(model_text + b"/* edited */\n")
    m = evidence.Model(evidence.load_inputs(SPEC, results, repo, TOOLS), "cmd")
    assert m.verdict == "FAIL"
    assert any("differs from the source tree" in p for p in m.problems)


def test_trace_links_are_resolved_to_needs(tmp_path):
    m = evidence.Model(evidence.load_inputs(SPEC, RESULTS, _repo_copy(tmp_path), TOOLS), "cmd")
    req = {r["id"]: r for r in m.requirements}
    assert [p["need"] for p in req["REQ-TG-001"]["model"]] == ["PROP_REQ_TG_001_repetition"]
    assert req["REQ-TG-001"]["unit"][0]["need"] == "TC_Receiver_RejectsRepetition"
    assert req["REQ-TG-012"]["assumptions"] == ["ASM-004"]     # cited in its source list
    cases = {c["id"]: c for f in m.test_files for s in f["suites"] for c in s["cases"]}
    assert cases["TC_Receiver_RejectsRepetition"]["verifies"] == ["REQ-TG-001"]
    assert cases["TC_Conformance_VectorReplay_Replays_TG_TRAP_017"]["vectors"] == ["TG-TRAP-017"]


# ------------------------------------------------------------------------------------------
# errors


def test_missing_trace_json_is_an_error_naming_the_file(tmp_path, capsys):
    results = _results_copy(tmp_path)
    (results / "trace.json").unlink()
    with pytest.raises(PipelineError, match=r"trace\.json not found") as exc:
        evidence.build(SPEC, results, _repo_copy(tmp_path), tmp_path / "out")
    assert str(results / "trace.json") in str(exc.value)
    rc = cli.main(["evidence", "--spec", str(SPEC), "--results", str(results),
                   "--src", str(tmp_path / "repo"), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 1
    assert err[-1].startswith("railproof_testgen: error: ")
    assert str(results / "trace.json") in err[-1]


def test_missing_spec_is_an_error(tmp_path):
    with pytest.raises(PipelineError, match="specification directory not found"):
        evidence.build(tmp_path / "nospec", RESULTS, _repo_copy(tmp_path), tmp_path / "out")
    (tmp_path / "emptyspec").mkdir()
    with pytest.raises(PipelineError, match="no requirement files"):
        evidence.build(tmp_path / "emptyspec", RESULTS, tmp_path / "repo", tmp_path / "out")


def test_malformed_result_names_file_and_line(tmp_path):
    results = _results_copy(tmp_path)
    (results / "spin" / "telegram.json").write_text('{"model": "m",\n "properties": [}\n')
    with pytest.raises(PipelineError, match=r"telegram\.json: malformed JSON at line 2"):
        evidence.load_inputs(SPEC, results, REPO)
    results = _results_copy(tmp_path, "r2")
    with (results / "vectors" / "telegram.jsonl").open("a") as fh:
        fh.write('{"id": "TG-TRAP-001", "requirements": [], "steps": []}\n')
    with pytest.raises(PipelineError, match="TG-TRAP-001: duplicate vector id"):
        evidence.load_inputs(SPEC, results, REPO)


def test_output_directory_may_not_overlap_the_sources(tmp_path):
    repo = _repo_copy(tmp_path)
    with pytest.raises(PipelineError, match="must not overlap the evidence sources"):
        evidence.build(SPEC, RESULTS, repo, repo / "evidence" / "out")
    with pytest.raises(PipelineError, match="must not be the source tree"):
        evidence.build(SPEC, RESULTS, repo, repo)


# ------------------------------------------------------------------------------------------
# full builds


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The fixture package rendered twice, into two different directories."""
    tmp = tmp_path_factory.mktemp("evidence")
    repo = _repo_copy(tmp)
    before = _snapshot(repo / "evidence")
    outs = []
    for name in ("out1", "out2"):
        res = evidence.build(SPEC, RESULTS, repo, tmp / name, TOOLS)
        outs.append((tmp / name, res))
    return {"repo": repo, "before": before, "outs": outs}


def test_html_names_every_requirement_and_property_verdict(built):
    out, res = built["outs"][0]
    html = out / "html"
    trace_page = (html / "traceability.html").read_text(encoding="utf-8")
    overview = (html / "overview.html").read_text(encoding="utf-8")
    for r in evidence.load_inputs(SPEC, RESULTS, REPO).requirements:
        assert f'id="{r["id"]}"' in trace_page, r["id"]        # one need per requirement
        assert r["id"] in overview
    spin = _read_json(RESULTS / "spin" / "telegram.json")
    mc = (html / "model_checking.html").read_text(encoding="utf-8")
    for p in spin["properties"]:
        nid = evidence.need_id("PROP", p["name"], upper=False)
        row = re.search(rf'<tr class="need[^"]*">\s*<td[^>]*><p><a [^>]*>{nid}</a></p></td>\s*'
                        rf'<td[^>]*><p>([a-z]+)</p></td>', mc)
        assert row and row.group(1) == p["verdict"], nid
    for mu in spin["mutants"]:
        assert evidence.need_id("MUT", mu["name"], upper=False) in mc
    assert "Result: PASS" in overview
    assert res["summary"]["verdict"] == "PASS"


def test_every_section_is_rendered(built):
    html = built["outs"][0][0] / "html"
    vec = (html / "vectors_telegram.html").read_text(encoding="utf-8")
    for line in (RESULTS / "vectors" / "telegram.jsonl").read_text().splitlines()[1:]:
        assert f'id="{json.loads(line)["id"]}"' in vec
    assert "<details" in vec
    tests = (html / "tests.html").read_text(encoding="utf-8")
    assert 'id="TC_Receiver_RejectsRepetition"' in tests
    assert "TF_conformance_conformance" in tests
    analysis = (html / "analysis.html").read_text(encoding="utf-8")
    for col in ("ber", "p_s", "p_miscorrect_block", "per_hour_crc", "per_hour_crc_mac",
                "telegrams_per_hour", "meets_target"):
        assert f"<p>{col}</p>" in analysis, col
    gen = (html / "test_generation.html").read_text(encoding="utf-8")
    assert "UR-TG-001" in gen and "27 / 30" in gen
    versions = (html / "tool_versions.html").read_text(encoding="utf-8")
    assert "6.5.2" in versions and "sphinx-needs" in versions
    needs = _read_json(html / "needs.json")
    assert "created" not in needs                        # reproducible needs.json
    assert (built["outs"][0][0] / "sphinx-warnings.log").read_text() == ""


def test_manifest_covers_inputs_and_html(built):
    out, res = built["outs"][0]
    manifest = _read_json(out / "manifest.json")
    assert manifest["schema"] == "railproof/manifest/1"
    paths = {a["path"]: a for a in manifest["artifacts"]}
    for f in sorted(RESULTS.rglob("*")):
        if f.is_file():
            rel = "inputs/results/" + f.relative_to(RESULTS).as_posix()
            assert paths[rel]["sha256"] == hashlib.sha256(f.read_bytes()).hexdigest(), rel
    assert "inputs/spec/requirements/telegram.yaml" in paths
    assert "inputs/tool-versions/tool-versions.json" in paths
    excluded = {e["path"] for e in manifest["excluded"]}
    assert {".doctrees/", "html/.buildinfo", "html/schema_violations.json"} <= excluded
    for f in sorted((out / "html").rglob("*")):
        rel = f.relative_to(out).as_posix()
        if f.is_file() and rel not in ("html/.buildinfo", "html/schema_violations.json"):
            assert paths[rel]["sha256"] == hashlib.sha256(f.read_bytes()).hexdigest(), rel
            assert paths[rel]["bytes"] == f.stat().st_size
    lines = (out / "manifest.sha256").read_text().splitlines()
    assert len(lines) == len(manifest["artifacts"]) + 1
    for line in lines:
        digest, rel = line.split("  ", 1)
        assert hashlib.sha256((out / rel).read_bytes()).hexdigest() == digest, rel


def test_two_builds_give_identical_manifests(built):
    (out1, _), (out2, _) = built["outs"]
    assert (out1 / "manifest.json").read_bytes() == (out2 / "manifest.json").read_bytes()
    assert (out1 / "manifest.sha256").read_bytes() == (out2 / "manifest.sha256").read_bytes()


def test_source_tree_is_never_written(built):
    assert _snapshot(built["repo"] / "evidence") == built["before"]


def test_failures_are_shown_and_fail_the_verdict(tmp_path):
    results = _results_copy(tmp_path)
    spin = _read_json(results / "spin" / "telegram.json")
    spin["properties"][0]["verdict"] = "violated"
    spin["properties"][0]["errors"] = 1
    spin["mutants"][0]["verdict"] = "survived"
    _write_json(results / "spin" / "telegram.json", spin)
    res = _read_json(results / "analysis" / "residual_error.json")
    res["cases"][-1]["meets_target"] = False
    _write_json(results / "analysis" / "residual_error.json", res)
    unit = results / "tests" / "unit" / "radio_unit.xml"
    unit.write_text(unit.read_text().replace(
        'name="RejectsRepetition" file="cpp/tests/unit/radio/receiver_test.cpp" line="20" '
        'status="run" result="completed" time="0.001" timestamp="2025-06-11T09:00:00.002" '
        'classname="Receiver" />',
        'name="RejectsRepetition" classname="Receiver" time="0.001">'
        '<failure message="expected REJ_REPEATED">receiver_test.cpp:31</failure></testcase>'))
    out = evidence.build(SPEC, results, _repo_copy(tmp_path), tmp_path / "out")
    problems = out["summary"]["problems"]
    assert out["summary"]["verdict"] == "FAIL"
    assert any("REQ_TG_001_repetition" in p and "violated" in p for p in problems)
    assert any("seq_modulus_8" in p and "survived" in p for p in problems)
    assert any("Receiver.RejectsRepetition" in p and "failure" in p for p in problems)
    assert any("residual_error.json" in p for p in problems)
    overview = (tmp_path / "out" / "html" / "overview.html").read_text(encoding="utf-8")
    assert "Result: FAIL" in overview and "survived" in overview
    tests = (tmp_path / "out" / "html" / "tests.html").read_text(encoding="utf-8")
    assert "receiver_test.cpp:31" in tests          # failure text, rendered by sphinx-test-reports
    assert "tr_failure" in tests


def test_missing_optional_inputs_are_noted(tmp_path):
    results = tmp_path / "results"
    results.mkdir()
    shutil.copy(RESULTS / "trace.json", results / "trace.json")
    out = evidence.build(SPEC, results, _repo_copy(tmp_path), tmp_path / "out")
    assert out["summary"]["verdict"] == "INCOMPLETE"
    html = tmp_path / "out" / "html"
    for page in ("model_checking", "test_generation", "tests", "analysis", "tool_versions"):
        assert "Not available in this run" in (html / f"{page}.html").read_text(encoding="utf-8"), page
    assert (tmp_path / "out" / "sphinx-warnings.log").read_text() == ""


def test_three_hundred_vectors_render(tmp_path):
    results = tmp_path / "results"
    scale_results(results, 300)
    out = evidence.build(SPEC, results, _repo_copy(tmp_path), tmp_path / "out", TOOLS)
    assert out["summary"]["counts"]["vectors"] == 300
    vec = (tmp_path / "out" / "html" / "vectors_telegram.html").read_text(encoding="utf-8")
    assert len(re.findall(r'<table class="need [^"]*needs_type_vec', vec)) == 300
    assert out["summary"]["verdict"] == "PASS"


def test_a_sphinx_error_fails_the_build(tmp_path):
    repo = _repo_copy(tmp_path)
    (repo / "evidence" / "pipeline.rst").write_text("Pipeline\n========\n\n.. no-such-directive::\n")
    with pytest.raises(PipelineError, match=r'sphinx-build failed .*pipeline\.rst:4: ERROR: '
                                            r'Unknown directive type "no-such-directive"'):
        evidence.build(SPEC, RESULTS, repo, tmp_path / "out")
    assert not (tmp_path / "out" / "manifest.json").exists()
