"""Tests of the evidence command on the fixture tree (fixtures/evidence: every capability of
a small registry with its results in the build's formats).

Most tests check the context the pages are rendered from (no Sphinx run); the package is
rendered by Sphinx once per test session (``rendered``) and once more by the determinism
test, and the HTML tests read that one rendering."""
from __future__ import annotations

import hashlib
import json
import re
import shutil
from pathlib import Path

import pytest

from evidence_fixture import (AWKWARD, RESULTS, SPEC, add_ctest_entry, assert_fails, context, edit_json,
                              edit_text, needs, read_json, repo_copy, table_rows, text_of, tree)
from railproof_testgen import __main__ as cli
from railproof_testgen import evidence
from railproof_testgen.errors import PipelineError
from railproof_testgen.evidence import chapters, junit, render


def _snapshot(top: Path) -> dict:
    return {p.relative_to(top).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(top.rglob("*")) if p.is_file()}


# ------------------------------------------------------------------------------------------
# text helpers and the JUnit reader


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
    assert evidence.rst_escape("test::") == r"test:\:"      # not a literal-block marker
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


def test_junit_parser_counts_errors_and_skips(tmp_path):
    xml = tmp_path / "r.xml"
    xml.write_text('<testsuites><testsuite name="S" tests="4">'
                   '<testcase classname="S" name="ok"/>'
                   '<testcase classname="S" name="bad"><failure message="x"/></testcase>'
                   '<testcase classname="S" name="boom"><error message="y"/></testcase>'
                   '<testcase classname="S" name="later"><skipped/></testcase>'
                   '</testsuite></testsuites>', encoding="utf-8")
    jf = evidence.parse_junit(xml, "tests/r.xml")
    assert [c.result for c in jf.cases] == ["passed", "failure", "error", "skipped"]
    assert jf.error_elements == 1 and jf.cases[1].message == "x"
    assert jf.reports_view is not None and jf.reports_view[0]["testcases"][2]["result"] == "passed"


def test_ctest_entries_are_classified_by_name():
    cases = {
        "tg.Receiver.RejectsRepetition": ("unit", "tests/unit/tg/tg.Receiver.RejectsRepetition.xml"),
        "br_offline.Margins.AreNonNegative": ("unit", "tests/unit/br_offline/br_offline.Margins.AreNonNegative.xml"),
        "conformance_lc": ("conformance", "tests/conformance/lc.xml"),
        "conformance_lc_rejects_empty_dir": ("conformance_check", None),
        "conformance_fault_FAULT_LC_STALE_CONFIRMATION":
            ("fault", "tests/faults/conformance_FAULT_LC_STALE_CONFIRMATION.xml"),
        "unit_fault_FAULT_SC_BRAKE_STRICT": ("fault", "tests/faults/unit_FAULT_SC_BRAKE_STRICT.xml"),
        "unit_faults_none_selected_br": ("fault_control", None),
        "conformance_faults_none_selected_br": ("fault_control", None),
        "no_seeded_fault_in_railproof_tg": ("fault_build", None),
        "seeded_fault_selector_in_railproof_tg_faults": ("fault_build", None),
        "testgen.test_evidence": ("testgen", "tests/testgen/test_evidence.xml"),
        "fuzz_frame_decode_600s": ("fuzz", None),
        "margins_fails_on_weakened_train": ("check", None),
    }
    for name, (kind, detail) in cases.items():
        got = junit.classify(name)
        assert (got[0], got[2]) == (kind, detail), name
    assert junit.classify("unit_fault_FAULT_X")[1] == {"via": "unit", "fault": "FAULT_X"}


def test_unit_links_of_the_trace_match_gtest_and_pytest_cases():
    gt = evidence.JUnitCase("Receiver", "Receiver", "RejectsRepetition", "passed", "0",
                            file="cpp/runtime/tg/tests/test_receiver.cpp")
    py = evidence.JUnitCase("pytest", "tests.test_params", "test_rejects_duplicate_id", "passed", "0")
    assert gt.matches("Receiver.RejectsRepetition")
    assert gt.matches("Receiver.RejectsRepetition", "cpp/runtime/tg/tests/test_receiver.cpp")
    assert not gt.matches("Receiver.RejectsRepetition", "cpp/offline/tg/tests/test_receiver.cpp")
    assert not gt.matches("Receiver.RejectsOutOfWindow")
    assert py.matches("testgen/tests/test_params.py::test_rejects_duplicate_id")


# ------------------------------------------------------------------------------------------
# the context of the fixture (no Sphinx)


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    return context(tmp=tmp_path_factory.mktemp("clean"))


def test_the_fixture_passes(clean):
    assert clean.verdict == "PASS", clean.problems
    c = clean.counts
    assert (c["capabilities"], c["requirements"], c["requirements_ok"]) == (5, 12, 12)
    assert (c["ctest_entries"], c["ctest_passed"]) == (57, 57)
    assert (c["vectors"], c["vectors_replayed_passed"], c["vectors_not_replayed"]) == (13, 13, 0)
    assert (c["seeded_faults"], c["seeded_faults_killed"]) == (6, 6)
    assert (c["proof_obligations"], c["proof_obligations_ok"]) == (2, 2)
    assert c["tests_rendered_from_xml"] == 1      # the pytest name with a newline
    assert clean.ignored_results == []


def test_chapters_follow_the_registry(clean):
    reg = read_json(RESULTS / "registry.json")["capabilities"]
    assert [ch["name"] for ch in clean.chapters] == [c["name"] for c in reg]
    assert chapters.module("tg") is None and chapters.module("mb") is not None
    tg = clean.chapter["tg"]
    assert [r["id"] for r in tg["requirements"]] == ["REQ-TG-001", "REQ-TG-010", "REQ-TG-012"]
    assert [r["id"] for r in clean.chapter["br"]["requirements"]] == ["REQ-BR-001", "REQ-BR-009", "REQ-SC-001"]
    md = tg["models"][0]
    assert [(c, n) for c, _, n in md["configurations"]] == [("default", 2), ("VARIANT_NARROW_WINDOW", 1)]
    assert "window edge W + 1 is reachable" in md["configurations"][1][1]    # the result's variant text
    assert [tf["rel"] for tf in tg["conformance"]] == ["tests/conformance/tg.xml"]
    assert [g["key"] for g in tg["unit_sets"]] == ["unit_tg", "unit_tg_offline"]
    assert [a["stem"] for a in tg["analyses"]] == ["residual_error"]
    assert [p["rel"] for p in clean.chapter["br"]["proofs"]] == ["proofs/br.json"]
    assert clean.chapter["br"]["studies"]["proofs"] == clean.chapter["br"]["proofs"]
    assert [p["src"] for p in clean.chapter["ra"]["plots"]] == ["plots/ra/dry_level_run.svg"]


def test_the_units_promised_by_the_registry_must_be_tested(tmp_path):
    """A registry with a units section (glue faults) promises the units' test set and a kill
    run per glue fault; the system page shows the faults and the scenarios' invariants."""
    spec, results, repo = tree(tmp_path)
    edit_json(results / "registry.json", lambda d: d.update(
        {"units": {"name": "units", "title": "The units", "faults": [
            {"id": "FAULT_UNIT_GLUE", "text": "a wire crossed", "killed_by": ["unit"]}]}}))
    ctx = evidence.context(spec, results, repo)
    assert ctx.verdict == "FAIL"
    assert "the units' test set (ctest entries units.*, results/tests/unit/units/) did not run" in ctx.problems
    assert "seeded fault FAULT_UNIT_GLUE (units): no ctest entry unit_fault_FAULT_UNIT_GLUE in this run" in ctx.problems
    assert [f["id"] for f in ctx.system["faults"]] == ["FAULT_UNIT_GLUE"]
    assert ctx.system["scenario_rows"] and len(ctx.system["invariants"][0]) == 1 + len(ctx.system["scenario_rows"])
    render.render_sources(ctx, repo / "evidence", tmp_path / "src")
    page = (tmp_path / "src" / "system.rst").read_text()
    assert ".. _chapter-units:" in page and ".. fault:: a wire crossed" in page


def test_a_capability_is_its_registry_entry_and_its_chapter_template(tmp_path):
    spec, results, repo = tree(tmp_path)
    edit_json(results / "registry.json", lambda d: d["capabilities"].append(
        {"name": "gn", "title": "GNSS positioning", "sources": ["D4"], "areas": ["GN"], "models": [],
         "design": "spec/design/gn.md", "chapter": "evidence/templates/gn.rst.jinja", "runtime_parts": [],
         "conformance": False, "proofs": False, "studies": [], "faults": []}))
    ctx = evidence.context(spec, results, repo)
    assert ctx.verdict == "PASS", ctx.problems
    with pytest.raises(PipelineError, match=r"gn\.rst\.jinja: gn: the registered capability has no "
                                            r"chapter template"):
        render.render_sources(ctx, repo / "evidence", tmp_path / "src0")
    (repo / "evidence" / "templates" / "gn.rst.jinja").write_text(
        "{% extends '_chapter.rst.jinja' %}\n{% block intro %}Position from GNSS.{% endblock %}\n")
    render.render_sources(ctx, repo / "evidence", tmp_path / "src")
    page = (tmp_path / "src" / "gn.rst").read_text()
    assert page.startswith("..") and "GNSS positioning\n================" in page
    assert "Position from GNSS." in page and "The registry lists no seeded fault" in page
    assert "   gn\n" in (tmp_path / "src" / "capabilities.rst").read_text()


def test_trace_links_are_resolved_to_needs(clean):
    req = {r["id"]: r for r in clean.requirements}
    assert [p["need"] for p in req["REQ-TG-001"]["model"]] == ["PROP_REQ_TG_001_repetition"]
    assert {p["id"] for p in req["REQ-TG-001"]["props"]} == \
        {"PROP_REQ_TG_001_repetition", "PROP_REQ_TG_001_repetition_VARIANT_NARROW_WINDOW"}
    assert {p["id"] for p in req["REQ-TG-012"]["props"]} == \
        {"PROP_REQ_TG_012_echo", "ASSERT_R_GUARANTEE_ECHO_AGE"}
    assert [mu["id"] for mu in req["REQ-TG-012"]["mutants"]] == ["MUT_MUTANT_ECHO_NEVER_EXPIRES"]
    assert req["REQ-TG-001"]["unit"][0]["need"] == "TC_Receiver_RejectsRepetition"
    assert [u["test"] for u in req["REQ-TG-012"]["unit_missing"]] == ["LLVMFuzzerTestOneInput"]
    assert req["REQ-TG-012"]["assumptions"] == ["ASM-004"]     # cited in its source list
    assert req["REQ-TG-001"]["vector_stats"] == {"total": 3, "passed": 3, "failed": 0, "skipped": 0,
                                                 "not_replayed": 0}
    cases = {c["id"]: c for f in clean.test_files for s in f["suites"] for c in s["cases"]}
    assert cases["TC_Receiver_RejectsRepetition"]["verifies"] == ["REQ-TG-001"]
    assert cases["TC_TelegramConformance_TG_TRAP_G0_train"]["vectors"] == ["TG-TRAP-G0-train"]
    assert cases["TC_TelegramConformance_VectorSet"]["vectors"] == []
    assert clean.vector_items["TG-TRAP-G0-train"]["cases"] == ["TC_TelegramConformance_TG_TRAP_G0_train"]


def test_every_registered_fault_is_listed_with_its_killers(clean):
    faults = {f["id"]: f for f in clean.faults}
    assert list(faults) == [f["id"] for c in read_json(RESULTS / "registry.json")["capabilities"]
                            for f in c["faults"]]
    tg = faults["FAULT_TG_NO_REPEAT_CHECK"]
    assert tg["verdict"] == "killed" and tg["killed_by"] == ["vectors", "unit"]
    assert [(k["how"], k["entry"], [x["name"] for x in k["killers"]]) for k in tg["kills"]] == [
        ("vectors", "conformance_fault_FAULT_TG_NO_REPEAT_CHECK", ["TG-TRAP-G0-train", "TG-RANDOM-S1-train"]),
        ("unit", "unit_fault_FAULT_TG_NO_REPEAT_CHECK", ["Receiver.RejectsRepetition"])]
    assert tg["needs"] == ["TC_Receiver_RejectsRepetition", "TG-RANDOM-S1-train", "TG-TRAP-G0-train"]
    assert faults["FAULT_SC_BRAKE_STRICT"]["needs"] == ["TC_SpeedCheck_BrakesAtTheLimit"]
    # the fault entries link to the fault, never to a rendered test file
    entries = {e["name"]: e for e in clean.entries}
    assert entries["unit_fault_FAULT_SC_BRAKE_STRICT"]["need"] == "FAULT_SC_BRAKE_STRICT"
    assert not any(tf["rel"].startswith("tests/faults/") for tf in clean.test_files)


def test_a_fault_without_a_killer_or_its_run_fails_the_verdict(tmp_path):
    spec, results, repo = tree(tmp_path)
    faults = results / "tests" / "faults"
    unit = faults / "unit_FAULT_TG_NO_REPEAT_CHECK.xml"
    unit.write_text(re.sub(r"<failure .*?</failure>", "", unit.read_text(), flags=re.S))
    (faults / "conformance_FAULT_MB_NO_TRAIN_MARGIN.xml").unlink()
    edit_text(results / "tests" / "ctest.junit.xml", 'name="unit_fault_FAULT_LC_STALE_CONFIRMATION"',
              'name="unit_fault_FAULT_LC_RENAMED"')
    ctx = evidence.context(spec, results, repo)
    assert_fails(ctx, "seeded fault FAULT_TG_NO_REPEAT_CHECK (tg): no unit test failed against it",
                 "seeded fault FAULT_MB_NO_TRAIN_MARGIN (mb): no result file "
                 "results/tests/faults/conformance_FAULT_MB_NO_TRAIN_MARGIN.xml",
                 "results/tests/faults/conformance_FAULT_MB_NO_TRAIN_MARGIN.xml: missing result file of "
                 "ctest entry conformance_fault_FAULT_MB_NO_TRAIN_MARGIN",
                 "seeded fault FAULT_LC_STALE_CONFIRMATION (lc): no ctest entry "
                 "unit_fault_FAULT_LC_STALE_CONFIRMATION in this run",
                 "ctest entry unit_fault_FAULT_LC_RENAMED: seeded fault FAULT_LC_RENAMED is not in the registry")
    assert {f["id"]: f["verdict"] for f in ctx.faults}["FAULT_RA_CONFIRM_TWO"] == "killed"


def test_failed_and_missing_tests_fail_the_verdict_and_stale_files_are_left_out(tmp_path):
    spec, results, repo = tree(tmp_path)
    ctest = results / "tests" / "ctest.junit.xml"
    edit_text(ctest, '<testcase name="fuzz_frame_decode_seeds" classname="fuzz_frame_decode_seeds" '
                     'time="0.05" status="run">',
              '<testcase name="fuzz_frame_decode_seeds" classname="fuzz_frame_decode_seeds" '
              'time="0.05" status="fail"><failure message="Failed"/>')
    (results / "tests" / "unit" / "mb" / "mb.Ground.KeepsTheTrainMargin.xml").unlink()
    stale = results / "tests" / "unit" / "tg" / "tg.Receiver.Removed.xml"
    shutil.copy(results / "tests" / "unit" / "tg" / "tg.Receiver.AcceptsInSequence.xml", stale)
    unit = results / "tests" / "unit" / "br" / "br.Supervisor.EmergencyBrakeInTime.xml"
    edit_text(unit, 'classname="Supervisor" />',
              'classname="Supervisor"><failure message="late">test_supervisor.cpp:31</failure></testcase>')
    ctx = evidence.context(spec, results, repo)
    assert_fails(ctx, "ctest entry fuzz_frame_decode_seeds: failure",
                 "results/tests/unit/mb/mb.Ground.KeepsTheTrainMargin.xml: missing result file of ctest "
                 "entry mb.Ground.KeepsTheTrainMargin",
                 "test Supervisor.EmergencyBrakeInTime (tests/unit/br/br.Supervisor.EmergencyBrakeInTime.xml): "
                 "failure")
    assert ctx.ignored_results == ["tests/unit/tg/tg.Receiver.Removed.xml"]
    assert "results/tests/unit/tg/tg.Receiver.Removed.xml" not in {f.rel for f in ctx.inp.files}
    # the REQ-MB-007 unit test has no result now
    req = {r["id"]: r for r in ctx.requirements}
    assert [u["test"] for u in req["REQ-MB-007"]["unit_missing"]] == ["Ground.KeepsTheTrainMargin"]


def test_missing_results_fail_the_verdict_with_the_file(tmp_path):
    spec, results, repo = tree(tmp_path)
    for rel in ("spin/ra.json", "vectors/lc.coverage.json", "vectors/br.jsonl", "proofs/br.json",
                "analysis/warning_study.json", "layout.json", "tool-versions.json",
                "tests/conformance/mb.xml", "tests/ctest.junit.xml"):
        (results / rel).unlink()
    ctx = evidence.context(spec, results, repo)
    assert_fails(
        ctx,
        "results/tests/ctest.junit.xml: the build's one ctest run (target test-results) wrote no results",
        "results/layout.json: the module-boundary check (layout) not written by the build",
        "results/tool-versions.json: the tool versions not written by the build",
        "results/spin/ra.json (model checking): not written for model ra of capability ra",
        "results/vectors/lc.coverage.json (goal coverage): not written for model lc of capability lc",
        "results/vectors/br*.jsonl (vectors): not written for model br of capability br",
        "results/proofs/br.json: the registry gives capability br proofs, the build wrote no result",
        "results/analysis/warning_study.json: no result of study warning_study of capability lc",
        "capability mb: no conformance run (ctest entry conformance_mb) in this run",
        "seeded fault FAULT_TG_NO_REPEAT_CHECK (tg): no ctest entry "
        "conformance_fault_FAULT_TG_NO_REPEAT_CHECK in this run")


def test_results_of_a_model_the_registry_does_not_know_fail(tmp_path):
    spec, results, repo = tree(tmp_path)
    shutil.copy(results / "spin" / "tg.json", results / "spin" / "xx.json")
    edit_json(results / "spin" / "xx.json", lambda d: d.update(model="models/xx.pml", properties=[],
                                                               assertions=[], mutants=[]))
    shutil.copy(results / "vectors" / "tg.coverage.json", results / "vectors" / "xx.coverage.json")
    ctx = evidence.context(spec, results, repo)
    assert "results/spin/xx.json: model-checking result of model xx, which the capability registry " \
           "does not list" in ctx.problems
    assert "results/vectors/xx.coverage.json: goal coverage of model xx, which the capability registry " \
           "does not list" in ctx.problems


def test_violations_fail_the_verdict(tmp_path):
    spec, results, repo = tree(tmp_path)

    def spin(d):
        d["properties"][0].update(verdict="violated", errors=1)
        d["assertions"][0]["verdict"] = "violated"
        d["mutants"][0]["verdict"] = "survived"
    edit_json(results / "spin" / "tg.json", spin)
    edit_json(results / "analysis" / "residual_error.json",
              lambda d: d["results"][-1].update(meets_target=False))
    edit_json(results / "analysis" / "odometry_study.json", lambda d: d.update(verdict="FAIL"))
    edit_json(results / "proofs" / "br.json", lambda d: d["obligations"][0]["z3"].update(verdict="sat"))
    edit_json(results / "layout.json", lambda d: d["violations"].append(
        "railproof_mb_onboard: railproof_mb_wayside: onboard code links wayside code"))
    edit_text(spec / "design" / "lc.md", "| ASM-001 |", "| ASM-099 |")
    ctx = evidence.context(spec, results, repo)
    assert_fails(ctx, "model property REQ_TG_001_repetition (models/tg.pml, configuration default): violated",
                 "model assertion R_GUARANTEE_ECHO_AGE (models/tg.pml): violated",
                 "mutant MUTANT_NO_REPEAT_CHECK (models/tg.pml): survived, expected rejected",
                 "analysis analysis/residual_error.json: target not met in results[1]",
                 "analysis analysis/odometry_study.json: target not met in verdict",
                 "proof proofs/br.json: obligation BR_a2_monotone.dmu2_d4 did not come back unsat from both solvers",
                 "module boundaries (layout.json): railproof_mb_onboard: railproof_mb_wayside: onboard code "
                 "links wayside code",
                 "peer cross-check (spec/design/lc.md §7) names unknown identifier(s) ASM-099")


def test_conformance_gaps_fail_the_verdict(tmp_path):
    spec, results, repo = tree(tmp_path)
    conf = results / "tests" / "conformance" / "tg.xml"
    text = conf.read_text(encoding="utf-8")
    text = re.sub(r'    <testcase name="TG_TRAP_G0_ground".*?</testcase>\n', "", text, flags=re.S)
    conf.write_text(text.replace('value="TG-RANDOM-S1-train"', 'value="TG-RANDOM-S99-train"'))
    edit_json(results / "vectors" / "br.coverage.json", lambda d: d["goals"][0].update(vectors=[]))
    ctx = evidence.context(spec, results, repo)
    assert ctx.vector_items["TG-TRAP-G0-ground"]["conformance"] == "not replayed"
    assert "2 vector(s) not replayed by any conformance test case (first: TG-TRAP-G0-ground)" in ctx.problems
    assert any("replays vector TG-RANDOM-S99-train, which is not in the vector files" in p for p in ctx.problems)
    assert "goal G0 (vectors/br.coverage.json): reached without vector" in ctx.problems


def test_model_hash_is_compared_with_the_source_tree(tmp_path):
    spec, results, repo = tree(tmp_path)
    ctx = evidence.context(spec, results, repo)
    assert {m["model_name"]: m["src_check"] for m in ctx.models}["lc"] == "matches the source tree"
    with (repo / "models" / "lc.pml").open("a") as fh:
        fh.write("/* edited */\n")
    ctx = evidence.context(spec, results, repo)
    assert "models/lc.pml: model hash in spin/lc.json differs from the source tree" in ctx.problems
    ctx = evidence.context(spec, results, repo_copy(tmp_path / "bare", with_models=False))
    assert {m["model_name"]: m["src_check"] for m in ctx.models}["lc"] == "model file not in the source tree"
    assert ctx.verdict == "PASS", ctx.problems


def test_analysis_results_are_flattened_into_tables(clean):
    a = next(x for x in clean.analyses if x["stem"] == "scenario_d5_follow_20kmh")
    scalars = dict(a["scalars"])
    assert scalars["channel.loss_probability"] == "0.01" and scalars["violation_list"] == "none"
    tables = {t["name"]: t for t in a["tables"]}
    assert tables["checks"]["columns"][:2] == ["key", "checks"]
    assert [r[0] for r in tables["checks"]["rows"]] == ["ASM-013", "REQ-MB-007", "REQ-MB-008"]
    sweep = next(x for x in clean.analyses if x["stem"] == "scenario_gap_sweep")
    assert "gap.settled_gap_m" in {t["name"]: t for t in sweep["tables"]}["runs"]["columns"]


def test_layout_is_read_as_runtime_offline_and_test_targets(clean):
    lay = clean.layout
    assert [r["name"] for r in lay["runtime"]] == ["railproof_core", "railproof_messages", "railproof_mb_onboard",
                                                   "railproof_mb_wayside", "railproof_tg"]
    onboard = next(r for r in lay["runtime"] if r["name"] == "railproof_mb_onboard")
    assert onboard["sides"] == ["common"] and onboard["offline"] == [] and onboard["external"] == ["PkgConfig::SODIUM"]
    assert lay["by_side"]["wayside"] == ["railproof_mb_wayside"]
    assert [r["name"] for r in lay["offline"]] == ["line_sim", "railproof_offline"]
    assert [r["name"] for r in lay["tests"]] == ["railproof_sim_tests", "railproof_tg_tests"]


def test_the_pass_verdict_is_stated_on_the_overview(clean, tmp_path):
    render.render_sources(clean, repo_copy(tmp_path) / "evidence", tmp_path / "src")
    overview = (tmp_path / "src" / "overview.rst").read_text()
    assert ".. admonition:: Result: PASS" in overview and "Result: FAIL" not in overview


# ------------------------------------------------------------------------------------------
# bad input: a clear error naming file, entry and reason, nothing written


def test_missing_trace_or_registry_is_an_error_naming_the_file(tmp_path, capsys):
    spec, results, repo = tree(tmp_path)
    (results / "trace.json").unlink()
    with pytest.raises(PipelineError, match=r"trace\.json not found") as exc:
        evidence.build(spec, results, repo, tmp_path / "out")
    assert str(results / "trace.json") in str(exc.value)
    rc = cli.main(["evidence", "--spec", str(spec), "--results", str(results), "--src", str(repo),
                   "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 1 and err[-1].startswith("railproof_testgen: error: ") and str(results / "trace.json") in err[-1]
    assert not (tmp_path / "out").exists()
    shutil.copy(RESULTS / "trace.json", results / "trace.json")
    (results / "registry.json").unlink()
    with pytest.raises(PipelineError, match=r"registry\.json: registry\.json not found"):
        evidence.load_inputs(spec, results, repo)


def test_malformed_inputs_name_file_entry_and_reason(tmp_path):
    spec, results, repo = tree(tmp_path)
    spin = results / "spin" / "tg.json"
    good = spin.read_text()
    spin.write_text('{"model": "m",\n "properties": [}\n')
    with pytest.raises(PipelineError, match=r"tg\.json: malformed JSON at line 2"):
        evidence.load_inputs(spec, results, repo)
    spin.write_text(good)
    with (results / "vectors" / "tg.jsonl").open("a") as fh:
        fh.write('{"id": "LC-TRAP-G0", "requirements": [], "steps": []}\n')
    with pytest.raises(PipelineError, match=r"tg\.jsonl: LC-TRAP-G0: duplicate vector id \(also in lc\.jsonl\)"):
        evidence.load_inputs(spec, results, repo)
    shutil.copy(RESULTS / "vectors" / "tg.jsonl", results / "vectors" / "tg.jsonl")
    edit_json(results / "registry.json", lambda d: d["capabilities"][1].update(faults={}))
    with pytest.raises(PipelineError, match=r"registry\.json: mb: 'faults' must be a list"):
        evidence.load_inputs(spec, results, repo)
    shutil.copy(RESULTS / "registry.json", results / "registry.json")
    (results / "tests" / "conformance" / "lc.xml").write_text("<testsuites><testsuite>")
    with pytest.raises(PipelineError, match=r"conformance/lc\.xml: malformed JUnit XML"):
        evidence.load_inputs(spec, results, repo)
    shutil.copy(RESULTS / "tests" / "conformance" / "lc.xml", results / "tests" / "conformance" / "lc.xml")
    add_ctest_entry(results, "spec_validate")
    with pytest.raises(PipelineError, match=r"ctest\.junit\.xml: spec_validate: two ctest entries of the same name"):
        evidence.load_inputs(spec, results, repo)
    shutil.copy(RESULTS / "tests" / "ctest.junit.xml", results / "tests" / "ctest.junit.xml")
    (results / "lc" / "warning_time_onboard.svg").write_text("not an image")
    with pytest.raises(PipelineError, match=r"warning_time_onboard\.svg: -: not an SVG image"):
        evidence.load_inputs(spec, results, repo)


def test_missing_spec_and_overlapping_output_are_errors(tmp_path):
    repo = repo_copy(tmp_path)
    with pytest.raises(PipelineError, match="specification directory not found"):
        evidence.build(tmp_path / "nospec", RESULTS, repo, tmp_path / "out")
    (tmp_path / "emptyspec").mkdir()
    with pytest.raises(PipelineError, match="no requirement files"):
        evidence.build(tmp_path / "emptyspec", RESULTS, repo, tmp_path / "out")
    with pytest.raises(PipelineError, match="must not overlap the evidence sources"):
        evidence.build(SPEC, RESULTS, repo, repo / "evidence" / "out")
    with pytest.raises(PipelineError, match="must not be the source tree"):
        evidence.build(SPEC, RESULTS, repo, repo)
    assert not (tmp_path / "out").exists()


def test_a_sphinx_error_fails_the_build_and_leaves_no_package(tmp_path, monkeypatch):
    src = tmp_path / "src"
    src.mkdir()
    (src / "conf.py").write_text("project = 'x'\n")
    (src / "index.rst").write_text("Index\n=====\n\n.. no-such-directive::\n")
    with pytest.raises(PipelineError, match=r'sphinx-build failed .*index\.rst:4: ERROR: '
                                            r'Unknown directive type "no-such-directive"'):
        render.run_sphinx(src, tmp_path / "html", tmp_path / "doctrees", tmp_path)
    # build() stops before anything is moved into the output directory
    out = tmp_path / "out"
    out.mkdir()
    (out / "manifest.json").write_text("{}")       # an earlier package is removed first

    def fail(*_):
        raise PipelineError("sphinx-build failed (exit 2, 1 error(s)): stop")
    monkeypatch.setattr(render, "run_sphinx", fail)
    with pytest.raises(PipelineError, match="stop"):
        evidence.build(SPEC, RESULTS, repo_copy(tmp_path), out)
    assert sorted(p.name for p in out.iterdir()) == []
    assert (tmp_path / "out.partial" / "src" / "index.rst").is_file()


# ------------------------------------------------------------------------------------------
# the rendered package: the fixture with the awkward JUnit names as two more tooling tests


def _render_inputs(tmp: Path) -> tuple:
    spec, results, repo = tree(tmp)
    for name in ("awkward_names", "unparsable_time"):
        shutil.copy(AWKWARD / f"{name}.xml", results / "tests" / "testgen" / f"test_{name}.xml")
    add_ctest_entry(results, "testgen.test_awkward_names", "fail", "3 failed")
    add_ctest_entry(results, "testgen.test_unparsable_time")
    return spec, results, repo


@pytest.fixture(scope="session")
def rendered(tmp_path_factory):
    """The package, rendered once for the session."""
    tmp = tmp_path_factory.mktemp("rendered")
    spec, results, repo = _render_inputs(tmp)
    before = _snapshot(repo / "evidence")
    res = evidence.build(spec, results, repo, tmp / "out")
    return {"tmp": tmp, "out": tmp / "out", "html": tmp / "out" / "html", "res": res, "repo": repo,
            "results": results, "before": before}


def _page(rendered, name: str) -> str:
    return (rendered["html"] / f"{name}.html").read_text(encoding="utf-8")


def test_the_package_renders_without_a_warning(rendered):
    res, out = rendered["res"], rendered["out"]
    assert res["warnings"] == 0 and (out / "sphinx-warnings.log").read_text() == ""
    assert not (out.parent / "out.partial").exists()
    summary = read_json(out / "evidence.json")
    assert summary == res["summary"] and summary["verdict"] == "FAIL"
    assert sorted(summary["problems"]) == [
        "ctest entry testgen.test_awkward_names: failure",
        "test testgen.tests.test_x.test_fails_plainly (tests/testgen/test_awkward_names.xml): failure",
        "test testgen.tests.test_x.test_raises_in_fixture (tests/testgen/test_awkward_names.xml): error",
        "test testgen.tests.test_x.test_same_name (tests/testgen/test_awkward_names.xml): failure"]
    overview = _page(rendered, "overview")
    assert "Result: FAIL" in overview and "test_raises_in_fixture" in overview


def test_every_requirement_and_property_verdict_is_shown(rendered):
    trace_page = _page(rendered, "traceability")
    for r in read_json(RESULTS / "trace.json")["requirements"]:
        page = (rendered["html"] / "requirements" / f"{r['id']}.html").read_text(encoding="utf-8")
        assert f'id="{r["id"]}"' in page, r["id"]
        assert f'href="requirements/{r["id"]}.html' in trace_page, r["id"]
    rows = {row[0]: row for row in table_rows(_page(rendered, "model_checking"))}
    for p in read_json(RESULTS / "spin" / "mb.json")["properties"]:
        nid = evidence.need_id("PROP", p["name"], upper=False)
        assert rows[nid][1:4] == [p["configuration"], p["verdict"], str(p["states_stored"])], nid
    assert rows["ASSERT_R_GUARANTEE_ECHO_AGE"][2] == "verified"
    assert rows["MUT_MUTANT_ECHO_NEVER_EXPIRES"][1:] == ["default", "rejected", "rejected",
                                                          "ASSERT_R_GUARANTEE_ECHO_AGE"]
    page = (rendered["html"] / "requirements" / "REQ-TG-001.html").read_text(encoding="utf-8")
    rows = {r[0]: r for r in table_rows(page)}
    assert rows["TG-TRAP-G0-train"][1:6] == ["trap", "train", "G0: REJ_REPEATED", "2", "passed"]
    assert rows["TC_Receiver_RejectsRepetition"][1] == "passed"
    assert "3 passed, 0 failed, 0 skipped, 0 not" in text_of(page)


def test_every_section_is_rendered(rendered):
    html = rendered["html"]
    for f in sorted((RESULTS / "vectors").glob("*.jsonl")):
        page = (html / f"vectors_{f.stem.replace('.', '_')}.html").read_text(encoding="utf-8")
        for line in f.read_text().splitlines()[1:]:
            assert f'id="{json.loads(line)["id"]}"' in page
        assert "<details" in page
    unit = (html / "tests_unit_tg.html").read_text(encoding="utf-8")
    assert 'id="TC_Receiver_RejectsRepetition"' in unit and 'id="TF_unit_tg_tg_Receiver_RejectsRepetition"' in unit
    tests = _page(rendered, "tests")
    assert "conformance_fault_FAULT_TG_NO_REPEAT_CHECK" in tests and 'href="tg.html#FAULT_TG_NO_REPEAT_CHECK"' in tests
    analysis = _page(rendered, "analysis")
    for col in ("ber", "p_s", "per_hour_crc", "per_hour_crc_mac", "gap.settled_gap_m"):
        assert f"<p>{col}</p>" in analysis, col
    gen = _page(rendered, "test_generation")
    assert "UR-TG-001" in gen and "UR-MB-001" in gen
    versions = _page(rendered, "tool_versions")
    assert "6.5.2" in versions and "sphinx-needs" in versions
    boundaries = text_of(_page(rendered, "boundaries"))
    assert "railproof_mb_onboard" in boundaries and "Violations : 0" in boundaries
    assert "created" not in read_json(html / "needs.json")          # reproducible needs.json


def test_each_capability_has_its_chapter_with_faults_and_plots(rendered):
    html = rendered["html"]
    caps = _page(rendered, "capabilities")
    for c in read_json(RESULTS / "registry.json")["capabilities"]:
        assert f'href="{c["name"]}.html"' in caps
        page = (html / f"{c['name']}.html").read_text(encoding="utf-8")
        assert c["title"] in page
        for f in c["faults"]:
            assert f'id="{f["id"]}"' in page, f["id"]
    assert 'href="capabilities.html"' in _page(rendered, "index")
    nd = needs(html)
    assert nd["FAULT_TG_NO_REPEAT_CHECK"]["killed_by"] == ["TC_Receiver_RejectsRepetition", "TG-RANDOM-S1-train",
                                                          "TG-TRAP-G0-train"]
    assert "FAULT_TG_NO_REPEAT_CHECK" in nd["TG-TRAP-G0-train"]["killed_by_back"]
    assert nd["TC_Receiver_RejectsRepetition"]["killed_by_back"] == ["FAULT_TG_NO_REPEAT_CHECK"]
    manifest = {a["path"]: a["sha256"] for a in read_json(rendered["out"] / "manifest.json")["artifacts"]}
    for d, name in (("scenarios", "d5_follow_20kmh"), ("ra", "dry_level_run"), ("br", "speed_check_design")):
        digest = hashlib.sha256((RESULTS / d / f"{name}.svg").read_bytes()).hexdigest()
        assert manifest[f"html/_images/{name}.svg"] == digest
        assert manifest[f"src/plots/{d}/{name}.svg"] == digest
        assert manifest[f"inputs/results/{d}/{name}.svg"] == digest
    assert 'src="_images/d5_follow_20kmh.svg"' in _page(rendered, "mb")
    assert "inputs/results/scenarios/d5_follow_20kmh.log.json" in manifest
    assert "inputs/spec/design/lc.md" in manifest and "inputs/source/models/tg.pml" in manifest


def test_awkward_junit_names_are_rendered_from_the_parsed_xml(rendered):
    res = rendered["res"]
    nd = needs(rendered["html"])
    cases = {nid: n for nid, n in nd.items() if n["type"] == "testcase"}
    awkward = sum(len(evidence.parse_junit(f, f.name).cases) for f in AWKWARD.glob("*.xml"))
    assert len(cases) == res["summary"]["counts"]["test_cases"] == 30 + awkward
    by_case = {}
    for n in cases.values():
        by_case.setdefault(n["case"], []).append(n["result"])
    assert by_case["test_same_name"] == ["passed", "failure"]
    assert by_case["test_raises_in_fixture"] == ["error"]
    assert by_case["test_skipped_blank"] == ["skipped"]
    assert by_case["test_nested[ [ [1, 2] ], [ [3] ] ]"] == ["passed"]
    assert by_case["\\x20 leading and trailing blanks \\x20"] == ["passed"]
    assert by_case["FirstCase"] == by_case["SecondCase"] == ["passed"]
    page = (rendered["html"] / "tests_testgen.html").read_text(encoding="utf-8")
    # exact names in literal blocks; failure text shown, never executed or interpreted
    assert '<pre><span></span>"test_nested[[[1, 2]], [[3]]]"' in page
    assert '<pre><span></span>"test_tab[a\\tb]"' in page
    assert '[[copy("id")]] is text here' in page
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in page and "<script>alert" not in page
    assert "tr_failure" in page
    assert "sphinx-test-reports fails on this file (ValueError)" in page
    tests = text_of(_page(rendered, "tests"))
    assert "Output of testgen.test_awkward_names (failure): 3 failed" in tests


def test_manifest_covers_inputs_sources_and_html(rendered):
    out, results = rendered["out"], rendered["results"]
    manifest = read_json(out / "manifest.json")
    assert manifest["schema"] == "railproof/manifest/1"
    paths = {a["path"]: a for a in manifest["artifacts"]}
    for f in sorted(results.rglob("*")):
        rel = f.relative_to(results).as_posix()
        if f.is_file():
            assert paths[f"inputs/results/{rel}"]["sha256"] == hashlib.sha256(f.read_bytes()).hexdigest(), rel
    assert "inputs/spec/requirements/tg.yaml" in paths and "inputs/results/tool-versions.json" in paths
    assert {".doctrees/", "html/.buildinfo", "html/schema_violations.json"} <= {e["path"] for e in manifest["excluded"]}
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


def test_two_renderings_of_the_same_inputs_give_the_same_manifest(rendered):
    tmp = rendered["tmp"]
    spec, results, repo = tmp / "spec", tmp / "results", rendered["repo"]
    evidence.build(spec, results, repo, tmp / "again")
    first, second = rendered["out"], tmp / "again"
    assert (first / "manifest.json").read_bytes() == (second / "manifest.json").read_bytes()
    assert (first / "manifest.sha256").read_bytes() == (second / "manifest.sha256").read_bytes()


def test_the_source_tree_is_never_written(rendered):
    assert _snapshot(rendered["repo"] / "evidence") == rendered["before"]
