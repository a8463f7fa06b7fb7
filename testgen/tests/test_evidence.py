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
AWKWARD = FIX / "junit_names"          # JUnit files with names no directive option can carry
# A trimmed pipeline run in the current formats (see its README.md).
PIPE = Path(__file__).resolve().parent / "fixtures" / "evidence_pipeline"
PIPE_SPEC, PIPE_RESULTS, PIPE_TOOLS = PIPE / "spec", PIPE / "results", PIPE / "tool-versions.json"


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


def _results_copy(tmp: Path, name: str = "results", src: Path = RESULTS) -> Path:
    dest = tmp / name
    shutil.copytree(src, dest)
    return dest


def _pipeline_repo(tmp: Path, with_model: bool = True) -> Path:
    """A repository root with the evidence sources and the model the pipeline fixture's
    results were computed from."""
    root = _repo_copy(tmp)
    if with_model:
        shutil.copytree(PIPE / "models", root / "models")
    return root


def _pipeline_model(tmp: Path, results: Path | None = None, with_model: bool = True):
    return evidence.Model(evidence.load_inputs(PIPE_SPEC, results or PIPE_RESULTS,
                                               _pipeline_repo(tmp, with_model), PIPE_TOOLS), "cmd")


def _table_rows(html: str, after: str = "") -> list:
    """The rows of every need table in html (after the first occurrence of ``after``), each
    a list of cell texts."""
    import html as html_mod
    if after:
        html = html[html.index(after):]
    rows = []
    for tb in re.findall(r'<table class="NEEDS_(?:TABLE|DATATABLES)[^"]*".*?</table>', html, re.S):
        for tr in re.findall(r"<tr[^>]*>(.*?)</tr>", tb, re.S):
            cells = re.findall(r"<t[dh][^>]*>(.*?)</t[dh]>", tr, re.S)
            rows.append([" ".join(html_mod.unescape(re.sub(r"<[^>]+>", " ", c)).split())
                         for c in cells])
    return rows


def _needs(html_dir: Path) -> dict:
    data = _read_json(html_dir / "needs.json")
    return next(iter(data["versions"].values()))["needs"]


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
    assert evidence.need_id("TS", "") == "TS_"            # at least three characters
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
    assert [c.result for c in jf.suites[0].cases] == ["passed", "failure", "error", "skipped"]
    assert jf.error_elements == 1
    assert jf.suites[0].cases[1].message == "x"
    assert jf.reports_view is not None and jf.reports_view[0]["testcases"][2]["result"] == "passed"


def test_display_text_and_plain_options():
    assert evidence.display_text("a[[1]]\nb\tc") == "a[ [1] ]\\nb\\tc"
    assert evidence.display_text(" x ") == "\\x20x\\x20"
    assert evidence.display_text("a\u2028b") == "a\\u2028b"
    assert evidence.display_text("") == "(empty)"
    assert evidence.display_text("ümlaut [1, 2] 'q'") == "ümlaut [1, 2] 'q'"
    for ok in ("TG_TRAP_G9_train", "test_x[a-b]", "- looks like a list", "a `b` \\ c"):
        assert evidence.plain_option(ok), ok
    for bad in ("", " x", "x ", "a  b", "a\nb", "a\tb", "x[[1]]", "x]]", "<<v>>", "ü"):
        assert not evidence.plain_option(bad), bad
    assert evidence.one_line("f([[1]])") == "f([ [1] ])"
    assert evidence.rst_escape("[[copy('id')]]") == "[ [copy('id')] ]"


def test_awkward_junit_names_are_rendered_from_the_parsed_xml(tmp_path):
    """Every case sphinx-test-reports cannot address exactly gets an own-rendered need
    with the reason; the others stay with sphinx-test-reports."""
    results = _results_copy(tmp_path)
    shutil.copytree(AWKWARD, results / "tests" / "awkward")
    m = evidence.Model(evidence.load_inputs(SPEC, results, _repo_copy(tmp_path)), "cmd")
    files = {f["rel"]: f for f in m.test_files}
    awk = files["tests/awkward/awkward_names.xml"]
    assert not awk["own"]                                    # the file itself is readable
    why = {}
    for s in awk["suites"]:
        for c in s["cases"]:
            why[(s["name"], c["name"])] = json.loads(c["own"])["note"] if c["own"] else ""
    assert why[("pytest", "plain_name_is_rendered_by_sphinx_test_reports")] == ""
    assert why[("pytest", "test_fails_plainly")] == ""
    for name in ("test_requirement_rules[    sil: 2\n--requirements/telegram.yaml-REQ-TG-003-"
                 "'sil' is a required property]", "  leading and trailing blanks  ",
                 "test_nested[[[1, 2]], [[3]]]", "test_tab[a\tb]", "", "test_variant[<<a>>]"):
        assert "one-line directive option" in why[("pytest", name)], name
    assert "JUnit <error>" in why[("pytest", "test_raises_in_fixture")]
    assert "empty literal block" in why[("pytest", "test_skipped_blank")]
    same = [c for s in awk["suites"] for c in s["cases"] if c["name"] == "test_same_name"]
    assert [c["result"] for c in same] == ["passed", "failure"]
    assert not same[0]["own"] and "same class and name" in json.loads(same[1]["own"])["note"]
    assert "nested suite" in why[("Outer/Inner", "NestedCase")]
    assert "same name" in why[("pytest", "second_suite_of_the_same_name")]
    assert "suite name" in why[("Suite\nwith newline", "InASuiteWithANewline")]
    assert "suite name" in why[("", "")]
    empty = [c for s in awk["suites"] if s["name"] == "" for c in s["cases"]]
    assert [c["id"] for c in empty] == ["TC_"]               # ids keep sphinx-needs' minimum length
    comma = files["tests/awkward/unparsable_time.xml"]
    assert "sphinx-test-reports fails on this file (ValueError)" in json.loads(comma["own"])["note"]
    assert all(c["own"] for s in comma["suites"] for c in s["cases"])
    assert m.test_totals == {"passed": 94, "failure": 2, "error": 1, "skipped": 2}
    assert m.verdict == "FAIL"


def test_awkward_junit_names_render_without_a_warning(tmp_path):
    results = _results_copy(tmp_path)
    shutil.copytree(AWKWARD, results / "tests" / "awkward")
    out = tmp_path / "out"
    res = evidence.build(SPEC, results, _repo_copy(tmp_path), out, TOOLS)
    assert res["warnings"] == 0 and (out / "sphinx-warnings.log").read_text() == ""
    problems = res["summary"]["problems"]
    assert sorted(p for p in problems if "awkward" in p) == [
        "test testgen.tests.test_x.test_fails_plainly (tests/awkward/awkward_names.xml): failure",
        "test testgen.tests.test_x.test_raises_in_fixture (tests/awkward/awkward_names.xml): error",
        "test testgen.tests.test_x.test_same_name (tests/awkward/awkward_names.xml): failure"]
    needs = _needs(out / "html")
    cases = {nid: n for nid, n in needs.items() if n["type"] == "testcase"}
    assert len(cases) == res["summary"]["counts"]["test_cases"] == 99
    by_case = {}
    for n in cases.values():
        by_case.setdefault(n["case"], []).append(n["result"])
    assert by_case["test_same_name"] == ["passed", "failure"]
    assert by_case["test_raises_in_fixture"] == ["error"]
    assert by_case["test_skipped_blank"] == ["skipped"]
    assert by_case["test_nested[ [ [1, 2] ], [ [3] ] ]"] == ["passed"]
    assert by_case["\\x20 leading and trailing blanks \\x20"] == ["passed"]
    assert by_case["FirstCase"] == by_case["SecondCase"] == ["passed"]
    tests = (out / "html" / "tests.html").read_text(encoding="utf-8")
    # exact names in literal blocks; failure text shown, never executed or interpreted
    assert '<pre><span></span>"test_nested[[[1, 2]], [[3]]]"' in tests
    assert '<pre><span></span>"test_tab[a\\tb]"' in tests
    assert '[[copy("id")]] is text here' in tests
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in tests and "<script>alert" not in tests


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
        page = (html / "requirements" / f"{r['id']}.html").read_text(encoding="utf-8")
        assert f'id="{r["id"]}"' in page, r["id"]              # one need per requirement
        assert f'href="requirements/{r["id"]}.html' in trace_page, r["id"]
        assert r["id"] in overview
    spin = _read_json(RESULTS / "spin" / "telegram.json")
    mc = (html / "model_checking.html").read_text(encoding="utf-8")
    rows = {row[0]: row for row in _table_rows(mc)}
    for p in spin["properties"]:
        nid = evidence.need_id("PROP", p["name"], upper=False)
        assert rows[nid][2] == p["verdict"], nid               # id; configuration; verdict
        assert rows[nid][3] == str(p["states_stored"]), nid
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
        'name="RejectsRepetition" file="cpp/runtime/tg/tests/receiver_test.cpp" line="20" '
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


# ------------------------------------------------------------------------------------------
# the pipeline's current formats (fixtures/evidence_pipeline)


def test_pipeline_formats_are_read(tmp_path):
    m = _pipeline_model(tmp_path)
    assert m.verdict == "PASS", m.problems
    # coverage lists several vectors per goal
    goals = {g["id"]: g for g in m.coverage[0]["goals"]}
    assert goals["G9"]["vector_needs"] == ["TG-TRAP-G9-ground", "TG-TRAP-G9-train"]
    assert goals["G12"]["status"] == "unreachable"
    assert "window edge" in goals["G12"]["justification_text"]
    # conformance cases link to the vector needs through their vector_id property
    cases = {c["id"]: c for f in m.test_files for s in f["suites"] for c in s["cases"]}
    assert cases["TC_TelegramConformance_TG_TRAP_G9_train"]["vectors"] == ["TG-TRAP-G9-train"]
    assert cases["TC_TelegramConformance_TG_RANDOM_HEALTHYS1_ground"]["vectors"] == \
        ["TG-RANDOM-HEALTHYS1-ground"]
    assert cases["TC_TelegramConformance_VectorSet"]["vectors"] == []
    assert {it["conformance"] for it in m.vector_items.values()} == {"passed"}
    assert m.vector_items["TG-BOUNDARY-G14-ground"]["cases"] == \
        ["TC_TelegramConformance_TG_BOUNDARY_G14_ground"]
    # properties keep their extra fields; the named assertion is a need of its own
    mo = m.models[0]
    props = {p["name"]: p for p in mo["properties"]}
    assert props["REQ_TG_016_availability"]["configuration"] == "HEALTHY"
    assert props["REQ_TG_001_repetition"]["transitions"] == "4676998"
    assert props["REQ_TG_001_repetition"]["command"].endswith("./pan -N REQ_TG_001_repetition")
    assertions = {a["name"]: a for a in mo["assertions"]}
    echo = assertions["assert:R_GUARANTEE_ECHO_AGE"]
    assert echo["verdict"] == "verified" and echo["links"] == ["REQ-TG-012"]
    assert "MUTANT_ECHO_NEVER_EXPIRES" in echo["basis"] and "all 11 verification runs" in echo["basis"]
    assert assertions["assert:LIVE_PEER_WHEN_UP"]["links"] == ["REQ-TG-004"]
    mutants = {mu["name"]: mu for mu in mo["mutants"]}
    assert mutants["MUTANT_ECHO_NEVER_EXPIRES"]["target"] == echo["id"] == "ASSERT_R_GUARANTEE_ECHO_AGE"
    assert "@OUT tx" in mutants["MUTANT_ECHO_NEVER_EXPIRES"]["counterexample"]
    # the requirement pages resolve trace.json's assertion links to the assertion needs
    req = {r["id"]: r for r in m.requirements}
    assert {p["id"] for p in req["REQ-TG-012"]["props"]} == \
        {"PROP_REQ_TG_009_turnaround", "ASSERT_R_GUARANTEE_ECHO_AGE"}
    assert req["REQ-TG-012"]["model_unresolved"] == []
    assert req["REQ-TG-012"]["vector_stats"] == {"total": 12, "passed": 12, "failed": 0,
                                                  "skipped": 0, "not_replayed": 0}
    assert len(req["REQ-TG-012"]["vectors"]) == 12 and req["REQ-TG-012"]["vectors_unresolved"] == []
    assert [u["test"] for u in req["REQ-TG-012"]["unit_missing"]] == ["LLVMFuzzerTestOneInput"]
    # the two parametrised pytest names with blanks and \n are rendered from the XML
    assert m.own_rendered == 2


def test_assertion_verdict_follows_the_runs_of_its_model(tmp_path):
    results = _results_copy(tmp_path, src=PIPE_RESULTS)
    spin = _read_json(results / "spin" / "telegram.json")
    spin["properties"][3]["errors"] = 1
    spin["properties"][3]["verdict"] = "violated"
    _write_json(results / "spin" / "telegram.json", spin)
    m = _pipeline_model(tmp_path / "a", results)
    echo = next(a for a in m.models[0]["assertions"] if a["label"] == "R_GUARANTEE_ECHO_AGE")
    assert echo["verdict"] == "not established"
    assert any("model assertion R_GUARANTEE_ECHO_AGE" in p and "not established" in p
               for p in m.problems)

    for p in spin["properties"]:
        p["errors"], p["verdict"] = 0, "verified"
        p["command"] = p["command"].replace("./pan -N", "./pan -A -N")
    _write_json(results / "spin" / "telegram.json", spin)
    m = _pipeline_model(tmp_path / "b", results)
    echo = next(a for a in m.models[0]["assertions"] if a["label"] == "R_GUARANTEE_ECHO_AGE")
    assert echo["verdict"] == "not checked" and m.verdict == "FAIL"


def test_a_property_checked_in_a_variant_gets_its_own_need(tmp_path):
    results = _results_copy(tmp_path, src=PIPE_RESULTS)
    spin = _read_json(results / "spin" / "telegram.json")
    variant = copy.deepcopy(spin["properties"][0])
    variant["configuration"] = "VARIANT_NARROW_WINDOW"
    spin["properties"].append(variant)
    _write_json(results / "spin" / "telegram.json", spin)
    m = _pipeline_model(tmp_path, results)
    ids = [p["id"] for p in m.models[0]["properties"] if p["name"] == "REQ_TG_001_repetition"]
    assert ids == ["PROP_REQ_TG_001_repetition",
                   "PROP_REQ_TG_001_repetition_VARIANT_NARROW_WINDOW"]
    req = {r["id"]: r for r in m.requirements}
    assert set(ids) <= {p["id"] for p in req["REQ-TG-001"]["props"]}
    assert m.verdict == "PASS", m.problems


def test_assertions_without_the_model_source_come_from_mutants_and_trace(tmp_path):
    m = _pipeline_model(tmp_path, with_model=False)
    names = {a["name"]: a for a in m.models[0]["assertions"]}
    assert set(names) == {"assert:R_GUARANTEE_ECHO_AGE", "assert:LIVE_PEER_WHEN_UP"}
    assert names["assert:R_GUARANTEE_ECHO_AGE"]["links"] == ["REQ-TG-012"]   # from trace.json
    assert "model source is not in this package" in names["assert:R_GUARANTEE_ECHO_AGE"]["origin"]
    assert m.models[0]["src_check"] == "model file not in the source tree"
    assert m.verdict == "PASS", m.problems


def test_conformance_gaps_fail_the_verdict(tmp_path):
    results = _results_copy(tmp_path, src=PIPE_RESULTS)
    conf = results / "tests" / "conformance.xml"
    text = conf.read_text(encoding="utf-8")
    # one vector loses its conformance case, another case names a vector that does not exist
    text = re.sub(r'    <testcase name="TG_TRAP_G9_train".*?</testcase>\n', "", text, flags=re.S)
    text = text.replace('value="TG-TRAP-G1-ground"', 'value="TG-TRAP-G99-ground"')
    conf.write_text(text, encoding="utf-8")
    m = _pipeline_model(tmp_path, results)
    assert m.vector_items["TG-TRAP-G9-train"]["conformance"] == "not replayed"
    assert "2 vector(s) not replayed by any conformance test case (first: TG-TRAP-G1-ground)" \
        in m.problems
    assert any("replays vector TG-TRAP-G99-ground, which is not in the vector files" in p
               for p in m.problems)
    assert m.verdict == "FAIL"

    cov = _read_json(results / "vectors" / "telegram.coverage.json")
    cov["goals"][0]["vectors"] = []
    _write_json(results / "vectors" / "telegram.coverage.json", cov)
    m = _pipeline_model(tmp_path / "b", results)
    assert any(p.startswith("goal G0 (vectors/telegram.coverage.json): reached without vector")
               for p in m.problems)


@pytest.fixture(scope="module")
def pipeline_built(tmp_path_factory):
    """The pipeline fixture rendered twice, into two directories."""
    tmp = tmp_path_factory.mktemp("pipeline")
    repo = _pipeline_repo(tmp)
    return [(tmp / name, evidence.build(PIPE_SPEC, PIPE_RESULTS, repo, tmp / name, PIPE_TOOLS))
            for name in ("out1", "out2")]


def test_pipeline_package_passes_without_warnings(pipeline_built):
    (out1, res1), (out2, _) = pipeline_built
    assert res1["summary"]["verdict"] == "PASS", res1["summary"]["problems"]
    assert res1["warnings"] == 0 and (out1 / "sphinx-warnings.log").read_text() == ""
    assert (out1 / "manifest.json").read_bytes() == (out2 / "manifest.json").read_bytes()
    c = res1["summary"]["counts"]
    assert (c["vectors"], c["vectors_replayed_passed"], c["vectors_not_replayed"]) == (42, 42, 0)
    assert (c["assertions"], c["assertions_verified"]) == (2, 2)
    assert c["test_cases"] == c["tests_passed"] == 253
    assert "inputs/source/models/tg.pml" in {a["path"] for a in _read_json(
        out1 / "manifest.json")["artifacts"]}


def test_requirement_page_shows_properties_vectors_and_conformance(pipeline_built):
    html = pipeline_built[0][0] / "html"
    page = (html / "requirements" / "REQ-TG-012.html").read_text(encoding="utf-8")
    rows = {r[0]: r for r in _table_rows(page)}
    # id; property; model; configuration; verdict; states; transitions; depth; time; memory
    assert rows["PROP_REQ_TG_009_turnaround"][3:9] == \
        ["default", "verified", "2468011", "4676998", "44", "2.28"]
    assert rows["ASSERT_R_GUARANTEE_ECHO_AGE"][1] == "assert:R_GUARANTEE_ECHO_AGE"
    assert rows["ASSERT_R_GUARANTEE_ECHO_AGE"][4] == "verified"
    assert rows["MUT_MUTANT_ECHO_NEVER_EXPIRES"][1:] == \
        ["rejected", "rejected", "ASSERT_R_GUARANTEE_ECHO_AGE"]
    # id; kind; role; goal; steps; conformance; replayed by
    assert rows["TG-TRAP-G9-train"][1:] == ["trap", "train", "G9: REJ_NO_ECHO", "2", "passed",
                                            "TC_TelegramConformance_TG_TRAP_G9_train"]
    assert rows["TG-RANDOM-S7-ground"][3] == "random walk, seed 7"
    assert "12 passed, 0 failed, 0 skipped, 0 not" in page
    # unit tests with their result; the fuzz target without one is listed
    unit = sorted(k for k in rows if k.startswith("TC_"))
    assert unit == ["TC_EndpointEcho_EchoValidityBoundaryAtMillisecondResolution",
                    "TC_EndpointEcho_OnlyTelegramsPassingChecksOneToSixUpdateTheEchoedNumber",
                    "TC_EndpointHandshake_GroundAndTrainBootstrapOverRealFrames",
                    "TC_EndpointSequence_GapIsReportedByTheInSequenceTelegramEvenIfI_1C00B16A"]
    assert {rows[k][1] for k in unit} == {"passed"}
    assert "LLVMFuzzerTestOneInput" in page
    tests = (html / "tests.html").read_text(encoding="utf-8")
    assert "replays vector" in tests and 'href="vectors_telegram.html#TG-TRAP-G9-train"' in tests
    mc = (html / "model_checking.html").read_text(encoding="utf-8")
    assert "MUTANT_ECHO_NEVER_EXPIRES, which breaks this assertion" in mc
