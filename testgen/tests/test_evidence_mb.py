"""Tests of the moving-block chapter of the evidence package: properties verified in
several configurations, configuration-specific vector files and goals, the conformance
file, the line simulator's summaries, gap sweep and plots (fixture: fixtures/evidence_mb,
laid over fixtures/evidence_pipeline)."""
from __future__ import annotations

import hashlib
import json
import re
import shutil
from pathlib import Path

import pytest

from railproof_testgen import evidence

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
PIPE = HERE / "fixtures" / "evidence_pipeline"
MB = HERE / "fixtures" / "evidence_mb"
MB_REQS = ("REQ-MB-007", "REQ-MB-008", "REQ-MB-018")


def _inputs(tmp: Path):
    """(spec, results, repo): the pipeline fixture with the moving-block fixture laid over
    it, and trace entries for the REQ-MB requirements."""
    spec, results = tmp / "spec", tmp / "results"
    shutil.copytree(PIPE / "spec", spec)
    shutil.copytree(PIPE / "results", results)
    shutil.copytree(MB / "spec", spec, dirs_exist_ok=True)
    shutil.copytree(MB / "results", results, dirs_exist_ok=True)
    trace = json.loads((results / "trace.json").read_text(encoding="utf-8"))
    for rid in MB_REQS:
        trace["requirements"].append({"id": rid, "area": "MB", "status": "ok", "links": {
            "model": [{"model": "models/mb.pml",
                       "property": f"REQ_MB_{rid[-3:]}_x", "verdict": "verified"}]}})
    (results / "trace.json").write_text(json.dumps(trace, indent=2) + "\n", encoding="utf-8")
    repo = tmp / "repo"
    shutil.copytree(REPO / "evidence", repo / "evidence",
                    ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(PIPE / "models", repo / "models")
    return spec, results, repo


def _text(html: str) -> str:
    import html as html_mod
    return " ".join(html_mod.unescape(re.sub(r"<[^>]+>", " ", html)).split())


def test_chapter_model_collects_the_moving_block_inputs(tmp_path):
    spec, results, repo = _inputs(tmp_path)
    m = evidence.Model(evidence.load_inputs(spec, results, repo, PIPE / "tool-versions.json"), "cmd")
    assert m.verdict == "PASS", m.problems
    mb = m.mb
    assert [r["id"] for r in mb["requirements"]] == list(MB_REQS)
    # property x configuration, grouped by property, configurations in the documented order
    assert [(p["name"], p["configuration"]) for p in mb["runs"]] == [
        ("REQ_MB_008_separation", "CORE"), ("REQ_MB_008_separation", "TRIO"),
        ("REQ_MB_008_separation", "FEATURE_POSS"), ("REQ_MB_007_limit", "CORE"),
        ("REQ_MB_007_limit", "FEATURE_ROUTE"), ("REQ_MB_018_progress", "FAIR")]
    assert len({p["id"] for p in mb["runs"]}) == 6                 # one need per run
    assert [c for c, _, _ in mb["configurations"]] == \
        ["CORE", "TRIO", "FEATURE_POSS", "FEATURE_ROUTE", "FAIR"]
    assert [mu["configuration"] for mu in mb["mutants"]] == ["CORE", "TRIO"]
    assert mb["goal_configs"] == [("default", 1, 1, 0), ("CORE", 1, 1, 0), ("FEATURE_ROUTE", 1, 0, 1)]
    assert [g["justification"] for g in mb["coverage"]["unreachable"]] == ["UR-MB-001"]
    files = {Path(v["vf"]["rel"]).name: v for v in mb["vector_files"]}
    assert files["moving_block.core.jsonl"]["configuration"] == "CORE"
    assert files["moving_block.jsonl"]["listed"] == "3"
    assert mb["vector_totals"]["count"] == mb["vector_totals"]["passed"] == 4
    # MB-TRAP-G1 is spelled inside the test name of MB-TRAP-G1-2: each replayed once
    assert m.vector_items["MB-TRAP-G1"]["cases"] == ["TC_MovingBlockConformance_moving_block_MB_TRAP_G1"]
    assert [tf["rel"] for tf in mb["conformance"]] == ["tests/conformance_mb.xml"]
    scen = {s["name"]: s for s in mb["scenarios"]}
    assert scen["d5_follow_20kmh"]["gap"] == "62.5" and scen["d1_faults"]["gap"] == "n/a"
    assert scen["d1_faults"]["faults"].startswith("radio_loss")
    assert scen["d1_faults"]["log"] == "scenarios/d1_faults.log.json"
    assert [r[0] for r in mb["sweeps"][0]["rows"]] == ["20", "40", "60"]
    assert [p["name"] for p in mb["plots"]] == ["d1_faults", "d5_follow_20kmh"]


def test_analysis_page_flattens_scenario_summaries(tmp_path):
    spec, results, repo = _inputs(tmp_path)
    m = evidence.Model(evidence.load_inputs(spec, results, repo), "cmd")
    a = next(x for x in m.analyses if x["stem"] == "scenario_d5_follow_20kmh")
    scalars = dict(a["scalars"])
    assert scalars["channel.loss_probability"] == "0.01" and scalars["violation_list"] == "none"
    tables = {t["name"]: t for t in a["tables"]}
    assert tables["checks"]["columns"][0] == "key"
    assert {"checks", "violations"} <= set(tables["checks"]["columns"])
    assert tables["checks"]["rows"][0][0] == "ASM-013"
    sweep = next(x for x in m.analyses if x["stem"] == "scenario_gap_sweep")
    assert "gap.settled_gap_m" in {t["name"]: t for t in sweep["tables"]}["runs"]["columns"]
    # a failing scenario fails the package
    d = json.loads((results / "analysis" / "scenario_d1_faults.json").read_text())
    d["result"] = "FAIL"
    (results / "analysis" / "scenario_d1_faults.json").write_text(json.dumps(d))
    m = evidence.Model(evidence.load_inputs(spec, results, repo), "cmd")
    assert "analysis analysis/scenario_d1_faults.json: target not met in result" in m.problems


@pytest.fixture(scope="module")
def mb_built(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("mb")
    spec, results, repo = _inputs(tmp)
    outs = [(tmp / n, evidence.build(spec, results, repo, tmp / n, PIPE / "tool-versions.json"))
            for n in ("out1", "out2")]
    return {"results": results, "outs": outs}


def test_chapter_renders_without_warnings_and_reproducibly(mb_built):
    (out1, res1), (out2, _) = mb_built["outs"]
    assert res1["summary"]["verdict"] == "PASS", res1["summary"]["problems"]
    assert res1["warnings"] == 0 and (out1 / "sphinx-warnings.log").read_text() == ""
    assert (out1 / "manifest.json").read_bytes() == (out2 / "manifest.json").read_bytes()


def test_chapter_shows_tables_and_embeds_every_plot(mb_built):
    out, _ = mb_built["outs"][0]
    html = (out / "html" / "moving_block.html").read_text(encoding="utf-8")
    text = _text(html)
    for rid in MB_REQS:
        assert f'href="requirements/{rid}.html#{rid}"' in html, rid
    for s in ("FEATURE_POSS", "Compositional argument", "MUTANT_TRIO_OVERLAP", "UR-MB-001",
              "moving_block.core.jsonl", "TF_conformance_mb", "Gap sweep: d5_follow_20kmh",
              "8800123", "95.25"):
        assert s in text, s
    manifest = {a["path"]: a["sha256"] for a in
                json.loads((out / "manifest.json").read_text())["artifacts"]}
    for name in ("d1_faults", "d5_follow_20kmh"):
        svg = mb_built["results"] / "scenarios" / f"{name}.svg"
        digest = hashlib.sha256(svg.read_bytes()).hexdigest()
        assert f'src="_images/{name}.svg"' in html, name
        assert manifest[f"html/_images/{name}.svg"] == digest
        assert manifest[f"src/scenario_plots/{name}.svg"] == digest
        assert manifest[f"inputs/results/scenarios/{name}.svg"] == digest
        assert f"inputs/results/scenarios/{name}.log.json" in manifest
    index = (out / "html" / "index.html").read_text(encoding="utf-8")
    assert 'href="moving_block.html"' in index
    analysis = (out / "html" / "analysis.html").read_text(encoding="utf-8")
    assert "settled_gap_m" in analysis
