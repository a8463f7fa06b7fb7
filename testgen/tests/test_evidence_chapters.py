"""Tests of the capability chapters of the evidence package (fixtures/evidence): what each
chapter gathers from the generic results, the content of its own that a chapter module adds
(moving block: scenarios; level crossings: peer cross-check), and the chapter pages as the
templates write them (reStructuredText; the HTML is checked in test_evidence.py)."""
from __future__ import annotations

from pathlib import Path

import pytest

from evidence_fixture import edit_json, read_json, repo_copy, tree
from railproof_testgen import evidence
from railproof_testgen.errors import PipelineError
from railproof_testgen.evidence import render


@pytest.fixture(scope="module")
def ctx(tmp_path_factory):
    return evidence.context(*tree(tmp_path_factory.mktemp("chapters")))


@pytest.fixture(scope="module")
def pages(ctx, tmp_path_factory):
    """The generated reStructuredText sources of the fixture (no Sphinx run)."""
    tmp = tmp_path_factory.mktemp("pages")
    render.render_sources(ctx, repo_copy(tmp) / "evidence", tmp / "src")
    return tmp / "src"


def test_runs_are_grouped_by_property_in_the_registry_order_of_configurations(ctx):
    mb = ctx.chapter["mb"]["models"][0]
    assert [(p["name"], p["configuration"]) for p in mb["runs"]] == [
        ("REQ_MB_008_separation", "CORE"), ("REQ_MB_007_limit", "CORE"), ("REQ_MB_018_progress", "FAIR")]
    assert [(c, n) for c, _, n in mb["configurations"]] == [("CORE", 2), ("FAIR", 1)]
    assert mb["configurations"][0][1].startswith("2 trains over the whole line")    # chapters/mb.py
    assert [mu["configuration"] for mu in mb["mutants"]] == ["CORE"]
    assert mb["goal_configs"] == [("CORE", 2, 1, 1)]
    assert [g["justification"] for g in mb["coverage"]["unreachable"]] == ["UR-MB-001"]
    files = {v["vf"]["name"]: v for v in mb["vector_files"]}
    assert (files["mb.core.jsonl"]["vf"]["configuration"], files["mb.core.jsonl"]["listed"]) == ("CORE", "2")
    assert files["mb.fair.jsonl"]["kinds"] == "random 1"
    assert mb["vector_totals"] == {"count": 3, "passed": 3, "failed": 0, "not_replayed": 0, "steps": 6}
    ra = ctx.chapter["ra"]["models"][0]
    assert [(c, n) for c, _, n in ra["configurations"]] == [("default", 1), ("ONE_START", 1)]
    assert ra["configurations"][1][1].startswith("one start point")      # the result's variant text
    assert not ctx.chapter["lc"]["models"][0]["described"]


def test_a_configuration_the_registry_does_not_list_is_shown_last(tmp_path):
    spec, results, repo = tree(tmp_path)
    edit_json(results / "spin" / "mb.json",
              lambda d: d["properties"].insert(0, dict(d["properties"][0], configuration="TRIO")))
    ctx = evidence.context(spec, results, repo)
    mb = ctx.chapter["mb"]["models"][0]
    assert [c for c, _, _ in mb["configurations"]] == ["CORE", "FAIR", "TRIO"]
    assert [(p["name"], p["configuration"]) for p in mb["runs"]] == [
        ("REQ_MB_008_separation", "CORE"), ("REQ_MB_008_separation", "TRIO"), ("REQ_MB_007_limit", "CORE"),
        ("REQ_MB_018_progress", "FAIR")]


def test_the_moving_block_chapter_shows_the_scenarios(ctx):
    mb = ctx.chapter["mb"]
    scen = {s["name"]: s for s in mb["scenarios"]}
    assert list(scen) == ["d5_follow_20kmh"]
    s = scen["d5_follow_20kmh"]
    assert (s["gap"], s["faults"], s["result"], s["trains"]) == ("62.5", "none", "PASS", 2)
    assert s["log"] == "scenarios/d5_follow_20kmh.log.json" and s["plot"] == "d5_follow_20kmh"
    assert [r[0] for r in mb["sweeps"][0]["rows"]] == ["20", "40", "60"]
    assert [(p["dir"], p["name"], p["scenario"]["name"]) for p in mb["plots"]] == [
        ("scenarios", "d5_follow_20kmh", "d5_follow_20kmh")]
    assert mb["plots_without_summary"] == []


def test_a_missing_scenario_study_fails(tmp_path):
    spec, results, repo = tree(tmp_path)
    for f in (results / "analysis").glob("scenario_*.json"):
        f.unlink()
    ctx = evidence.context(spec, results, repo)
    assert "results/analysis/scenario_*.json: no result of study scenarios of capability mb" in ctx.problems
    assert ctx.chapter["mb"]["plots_without_summary"] == ["d5_follow_20kmh"]


def test_the_braking_chapter_holds_proofs_and_studies(ctx):
    br = ctx.chapter["br"]
    rows = br["proofs"][0]["rows"]
    assert [(r["expected"], r["z3"][0], r["cvc5"][0], r["ok"]) for r in rows] == [
        ("unsat", "unsat", "unsat", True), ("sat", "sat", "sat", True)]
    assert set(rows[1]["counterexample"]) == {"z3", "cvc5"}
    assert [a["stem"] for a in br["analyses"]] == ["speed_check_design", "margins"]
    assert [f["id"] for f in br["faults"]] == ["FAULT_BR_EMERGENCY_LATE", "FAULT_SC_BRAKE_STRICT"]


def test_the_level_crossing_chapter_checks_the_peer_table(ctx, tmp_path):
    lc = ctx.chapter["lc"]
    assert lc["peer_header"] == ["Failure mode of the case study", "Covered by"]
    assert [r["ids"] for r in lc["peer_rows"]] == [["HAZ-002", "REQ-LC-001"], ["REQ-LC-002"], ["ASM-001"]]
    spec, results, repo = tree(tmp_path)
    (spec / "design" / "lc.md").write_text("# lc\n\n## 7. Peer cross-check\n\n| a | b |\n|---|---|\n| x |\n")
    with pytest.raises(PipelineError, match=r"lc\.md: table row 1: 1 cells where the header has 2"):
        evidence.context(spec, results, repo)


def test_chapter_pages_hold_every_section(ctx, pages):
    for ch in ctx.chapters:
        page = (pages / f"{ch['name']}.rst").read_text()
        assert page.startswith(".. This page is generated"), ch["name"]
        assert f".. _chapter-{ch['name']}:" in page
        for heading in ("Requirements", "Conformance run", "Unit tests", "Seeded faults", "Studies", "Plots"):
            assert f"\n{heading}\n{'-' * len(heading)}\n" in page, (ch["name"], heading)
        for f in ch["faults"]:
            assert f".. fault:: {f['text']}\n   :id: {f['id']}\n   :capability: {ch['name']}\n" in page
        for p in ch["plots"]:
            assert f".. figure:: {p['src']}" in page and (pages / p["src"]).is_file()
    br = (pages / "br.rst").read_text()
    assert "Proofs (SMT, two solvers)" in br and "Worst-case margins" in br
    assert r"design\_curve.points" not in br and r":design\_curve.asymptote\_n1f: 400" in br
    assert "Peer cross-check\n----------------" in (pages / "lc.rst").read_text()
    mb = (pages / "mb.rst").read_text()
    assert "**Compositional argument.**" in mb and "Gap sweep: d5_follow_20kmh" in mb
    tg = (pages / "tg.rst").read_text()
    assert ":need:`ASSERT_R_GUARANTEE_ECHO_AGE`" in tg and "residual error" in tg
    assert "Proofs (SMT" not in tg


def test_fault_needs_link_their_killers(ctx, pages):
    tg = (pages / "tg.rst").read_text()
    assert ("   :killed_by: TC_Receiver_RejectsRepetition, TG-RANDOM-S1-train, TG-TRAP-G0-train\n" in tg)
    assert "2 vector(s) failed: :need:`TG-TRAP-G0-train`, :need:`TG-RANDOM-S1-train`." in tg
    faults = (pages / "seeded_faults.rst").read_text()
    for f in read_json(Path(ctx.inp.results_dir) / "registry.json")["capabilities"]:
        for fault in f["faults"]:
            assert f":need:`{fault['id']}`" in faults
