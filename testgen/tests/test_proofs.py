"""SMT proof obligations (``railproof_testgen proofs``): generation from spec/, replay by
z3 and cvc5, the deliberately wrong obligations, failure modes and the trace link."""
from __future__ import annotations

import copy
import json
import os
import re
import shutil
from fractions import Fraction
from pathlib import Path

import pytest
import yaml

from conftest import REPO, edit
from railproof_testgen import proofs
from railproof_testgen.trace import build_trace

SPEC = REPO / "spec"
PROOFS = REPO / "proofs"
TRAINS = sorted(p.stem for p in (SPEC / "trains").glob("*.yaml"))
PER_TRAIN = ["BR_a_stop", "BR_a_wrong_noerror", "BR_a_wrong_nocycle", "BR_a_target",
             "BR_a_inductive", "BR_a_invariant", "BR_a2_rounding", "BR_a2_monotone"]
ONCE = ["BR_lemma_braking", "BR_lemma_conservative", "BR_lemma_runup", "BR_lemma_target",
        "BR_b_moving_block", "BR_b_wrong_nomargin", "BR_c_d2_buffer", "BR_c_wrong_notau"]
WRONG = {"BR_a_wrong_noerror", "BR_a_wrong_nocycle", "BR_b_wrong_nomargin", "BR_c_wrong_notau"}


@pytest.fixture(scope="module")
def replay():
    """The pipeline's replay of the real obligations (build step `proofs`, results/proofs): the
    tests read it instead of running the solvers again. Without RAILPROOF_RESULTS_DIR (the
    build's results directory; ctest sets it) these tests are skipped."""
    results = os.environ.get("RAILPROOF_RESULTS_DIR")
    if not results:
        pytest.skip("RAILPROOF_RESULTS_DIR is not set: no pipeline results to check")
    out = Path(results) / "proofs"
    if not (out / "br.json").is_file():
        pytest.fail(f"{out / 'br.json'}: missing: the pipeline's proof results (build the target first)")
    return out, json.loads((out / "br.json").read_text(encoding="utf-8"))


def _value(text):
    """A model value of either solver as a Fraction: 3, 1/2, 1.5, (- 2.0), (/ 1 3)."""
    t = proofs._sexprs(text.replace("?", ""), ("model", "-"))[0]

    def ev(x):
        if isinstance(x, str):
            return Fraction(x)
        if x[0] == "-" and len(x) == 2:
            return -ev(x[1])
        if x[0] == "/" and len(x) == 3:
            return ev(x[1]) / ev(x[2])
        raise ValueError(text)

    return ev(t)


# ------------------------------------------------------------------- generation ----
def test_generation_is_deterministic_and_covers_every_train(tmp_path):
    caps1, inputs1 = proofs.generate(SPEC, PROOFS, tmp_path / "a")
    caps2, inputs2 = proofs.generate(SPEC, PROOFS, tmp_path / "b")
    files_a = sorted(p.name for p in (tmp_path / "a" / "br").glob("*.smt2"))
    files_b = sorted(p.name for p in (tmp_path / "b" / "br").glob("*.smt2"))
    assert files_a == files_b
    for name in files_a:
        assert (tmp_path / "a" / "br" / name).read_bytes() == \
            (tmp_path / "b" / "br" / name).read_bytes()
    assert inputs1 == inputs2
    names = [i.name for i in caps1["br"]]
    assert names == [i.name for i in caps2["br"]]
    expected = {f"{o}.{t}" for o in PER_TRAIN for t in TRAINS} | set(ONCE)
    assert set(names) == expected
    assert not any("weak" in n for n in names)  # spec/trains/mutants is not instantiated
    # parameters come from spec/: the free-running maximum of every train type
    for t in TRAINS:
        tf = yaml.safe_load((SPEC / "trains" / f"{t}.yaml").read_text())["braking"][
            "emergency_free_running_ms"][1]
        text = (tmp_path / "a" / "br" / f"BR_a_stop.{t}.smt2").read_text()
        assert f"(define-fun TF_MAX () Real (/ {tf}.0 1000.0))" in text
        assert "{{" not in text and "@obligation" not in text
    assert "spec/parameters/mb.yaml" in inputs1
    assert "proofs/br/lemmas.smt2.in" in inputs1


def test_lemma_uses_are_linked_to_their_proofs(tmp_path):
    caps, _ = proofs.generate(SPEC, PROOFS, tmp_path)
    by = {i.name: i for i in caps["br"]}
    assert by["BR_a_stop.emu3_d1"].use_names == ["BR_lemma_braking", "BR_lemma_runup"]
    assert by["BR_a2_rounding.emu3_d1"].use_names == ["BR_lemma_conservative"]
    assert list(by["BR_lemma_target"].proves) == ["lemma_target"]


# ----------------------------------------------------------------------- replay ----
def test_command_proves_every_obligation_with_both_solvers(replay):
    out, data = replay
    assert data["verdict"] == "pass" and not data.get("problems")
    assert data["solvers"]["z3"]["package"] == "z3-solver==5.4.0.0"
    assert data["solvers"]["cvc5"]["package"] == "cvc5==1.4.2"
    assert data["solvers"]["z3"]["version"].startswith("5.4.0")
    assert data["solvers"]["cvc5"]["version"].startswith("1.4.2")
    for r in ("REQ-BR-001", "REQ-BR-005", "REQ-BR-007", "REQ-BR-008", "REQ-BR-014",
              "REQ-BR-015", "REQ-BR-016"):
        assert r in data["requirements"]
    rows = data["obligations"]
    assert len(rows) == len(PER_TRAIN) * len(TRAINS) + len(ONCE)
    for row in rows:
        assert row["agree"] and row["meets_target"], row
        for s in ("z3", "cvc5"):
            assert row[s]["verdict"] == row["expected"], row
            assert isinstance(row[s]["time_s"], float) and row[s]["time_s"] >= 0
        if row["obligation"] not in WRONG:
            assert row["expected"] == "unsat", row["name"]
            # non-vacuous: a model of the hypotheses, confirmed by the other solver
            hyp = row["hypotheses"]
            assert {hyp["witness"], hyp["confirmed_by"]} == {"z3", "cvc5"}, row["name"]
            assert (out / "br" / "hypotheses" / f"{row['name']}.smt2").is_file()
        assert (out / row["smt2"]).is_file()
        assert (out / "br" / f"{row['name']}.z3.log").read_text().startswith(
            row["expected"])


def test_wrong_obligations_are_refuted_with_counterexamples(replay):
    _out, data = replay
    rows = {r["name"]: r for r in data["obligations"]}
    wrong = [r for r in rows.values() if r["obligation"] in WRONG]
    assert len(wrong) == 2 * len(TRAINS) + 2
    for row in wrong:
        assert row["expected"] == "sat" and row["mutations"]
        for s in ("z3", "cvc5"):
            assert row[s]["verdict"] == "sat" and row[s]["model"], (row["name"], s)
    for t in TRAINS:
        for s in ("z3", "cvc5"):
            m = {k: _value(v) for k, v in rows[f"BR_a_wrong_noerror.{t}"][s]["model"].items()
                 if k in ("e_f", "z", "x_m", "m")}
            assert m["e_f"] > 0 and m["z"] > m["x_m"], (t, s, m)  # uses the front error
    for s in ("z3", "cvc5"):
        m = rows["BR_b_wrong_nomargin"][s]["model"]
        assert _value(m["f_t"]) >= _value(m["r_t"])  # follower front at the leader's rear


def test_a_train_violating_the_design_rule_breaks_the_soundness_proof(tmp_path):
    """The negative-test train (real deceleration below its pattern deceleration) makes
    BR_a_stop satisfiable: the obligation depends on the parameters it is generated from."""
    model, values = proofs.load_spec(SPEC)
    weak = yaml.safe_load((SPEC / "trains" / "mutants" / "emu3_d1_weak.yaml").read_text())
    values.trains["emu3_d1_weak"] = weak
    values.train_files["emu3_d1_weak"] = SPEC / "trains" / "mutants" / "emu3_d1_weak.yaml"
    gen = proofs.Generator(SPEC, PROOFS, values, model["requirements"])
    insts = [i for i in gen.instances(PROOFS / "br") if i.name == "BR_a_stop.emu3_d1_weak"]
    assert len(insts) == 1
    path = tmp_path / "weak.smt2"
    path.write_text(insts[0].smt2)
    for s in ("z3", "cvc5"):
        res = proofs.run_solver(s, path, 120, insts[0].template.options[s])
        assert res["verdict"] == "sat", (s, res)
        assert _value(res["model"]["beta_real"]) < 1000


# --------------------------------------------------------------- failure modes ----
def _fake(flip=None, verdict=None):
    """A stand-in solver answering each obligation's expected verdict, except ``flip``:
    (solver, name) answered with ``verdict``."""

    def run(solver, path, timeout_s, options):
        text = Path(path).read_text()
        exp = re.search(r"^; expected verdict: (\w+)", text, re.M).group(1)
        name = Path(path).name[:-len(".smt2")]
        v = verdict if flip == (solver, name) else exp
        res = {"verdict": v, "time_s": 0.001, "wall_s": 0.01, "version": "fake",
               "package": "fake==0"}
        if v == "sat":
            res["model"] = {"x": "1"}
        if v in ("unknown", "timeout"):
            res["reason"] = "canceled"
        return res

    return run


@pytest.mark.parametrize("flip,verdict,fragment", [
    (("cvc5", "BR_a_stop.emu3_d1"), "sat", "BR_a_stop.emu3_d1: solvers disagree (z3 unsat, cvc5 sat)"),
    (("z3", "BR_b_wrong_nomargin"), "unsat", "BR_b_wrong_nomargin: solvers disagree"),
    (("z3", "BR_c_d2_buffer"), "timeout", "BR_c_d2_buffer: z3 gave timeout"),
    (("cvc5", "BR_a2_rounding.dmu2_d4"), "unknown", "cvc5 gave unknown"),
])
def test_disagreement_unknown_and_timeout_fail(monkeypatch, cli, tmp_path, flip, verdict,
                                               fragment):
    monkeypatch.setattr(proofs, "run_solver", _fake(flip, verdict))
    res = cli("proofs", "--spec", SPEC, "--proofs", PROOFS, "--out", tmp_path)
    assert res.rc == 1
    errors = [ln for ln in res.err.splitlines() if ln.startswith("railproof_testgen: error:")]
    assert len(errors) == 1 and fragment in errors[0], res.err
    data = json.loads((tmp_path / "br.json").read_text())
    assert data["verdict"] == "fail"
    row = next(r for r in data["obligations"] if r["name"] == flip[1])
    assert row["meets_target"] is False and fragment.split(": ", 1)[-1] in row["problem"]


def test_both_solvers_with_the_unexpected_verdict_fail(monkeypatch, cli, tmp_path):
    def both_sat(solver, path, timeout_s, options):
        res = _fake()(solver, path, timeout_s, options)
        if Path(path).name == "BR_c_d2_buffer.smt2":
            res = dict(res, verdict="sat", model={"v": "1"})
        return res

    monkeypatch.setattr(proofs, "run_solver", both_sat)
    res = cli("proofs", "--spec", SPEC, "--proofs", PROOFS, "--out", tmp_path)
    assert res.rc == 1 and "BR_c_d2_buffer: both solvers sat, expected unsat" in res.err
    assert "proofs: [" in res.err  # progress, one line per obligation


def test_a_failed_lemma_fails_the_obligations_resting_on_it(monkeypatch, cli, tmp_path):
    monkeypatch.setattr(proofs, "run_solver", _fake(("z3", "BR_lemma_runup"), "sat"))
    res = cli("proofs", "--spec", SPEC, "--proofs", PROOFS, "--out", tmp_path)
    assert res.rc == 1
    data = json.loads((tmp_path / "br.json").read_text())
    stop = next(r for r in data["obligations"] if r["name"] == "BR_a_stop.emu3_d1")
    assert stop["meets_target"] is False and "BR_lemma_runup" in stop["problem"]


def test_contradictory_hypotheses_are_a_vacuous_proof(cli, tmp_path):
    """An obligation whose hypotheses contradict each other is 'proved' by both solvers,
    but the non-vacuity check (hypotheses without the claim must be satisfiable) fails."""
    pr = tmp_path / "proofs"
    (pr / "br").mkdir(parents=True)
    text = (PROOFS / "br" / "br_c_d2_buffer.smt2.in").read_text()
    assert "(assert (<= 0 v))\n" in text
    (pr / "br" / "br_c_d2_buffer.smt2.in").write_text(
        text.replace("(assert (<= 0 v))\n", "(assert (<= 0 v))\n(assert (< v 0.0))\n", 1))
    res = cli("proofs", "--spec", SPEC, "--proofs", pr, "--out", tmp_path / "out")
    assert res.rc == 1
    assert "BR_c_d2_buffer: its hypotheses were not shown satisfiable" in res.err, res.err
    data = json.loads((tmp_path / "out" / "br.json").read_text())
    row = next(r for r in data["obligations"] if r["name"] == "BR_c_d2_buffer")
    assert row["z3"]["verdict"] == row["cvc5"]["verdict"] == "unsat"
    assert row["meets_target"] is False and "unsatisfiable" in row["hypotheses"]["reason"]


def _copy(tmp_path, src):
    """A copy of the directory src (SPEC or PROOFS) in tmp_path, of the same name."""
    d = tmp_path / src.name
    shutil.copytree(src, d)
    return d


@pytest.mark.parametrize("file,old,new,where,reason", [
    ("trains/emu3_d1.yaml", "emergency_pattern_mm_s2: 1000", "emergency_pattern_mm_s2: -1000",
     "trains/emu3_d1.yaml", "-1000"),
    ("parameters/br.yaml", "value: 9807", "value: 0",
     "parameters/br.yaml: gravity_mm_s2", "must be positive"),
    # a negative distance is refused by the parameter schema (spec/design/data.md §1.2)
    # before the proofs' own check
    ("parameters/mb.yaml", "value: 3000\n    unit: mm\n    source: ASM-017",
     "value: -3000\n    unit: mm\n    source: ASM-017",
     "parameters/mb.yaml: setback_max_mm", "value: -3000 is less than the minimum of 0"),
])
def test_bad_parameter_fails_with_file_entry_and_reason(cli, tmp_path, file, old, new, where,
                                                        reason):
    spec = _copy(tmp_path, SPEC)
    edit(spec / file, old, new)
    res = cli("proofs", "--spec", spec, "--proofs", PROOFS, "--out", tmp_path / "out")
    assert res.rc == 1
    errors = [ln for ln in res.err.splitlines() if ln.startswith("railproof_testgen: error:")]
    assert len(errors) == 1 and where in errors[0] and reason in errors[0], res.err
    assert not (tmp_path / "out" / "br.json").exists()


@pytest.mark.parametrize("file,old,new,fragment", [
    ("br_c_d2_buffer.smt2.in", "{{MB.d2_tau_ms|real}}", "{{MB.d2_tau|real}}",
     "no parameter 'd2_tau'"),
    ("br_c_d2_buffer.smt2.in", "REQ-BR-016 : with", "REQ-BR-099 : with",
     "unknown requirement REQ-BR-099"),
    ("br_b_moving_block.smt2.in", '@mutate "(assert (<= m (- ext_rear margin)))"',
     '@mutate "(assert (<= m (- ext_rear gap)))"', "occurs 0 times"),
    ("br_b_moving_block.smt2.in", "; @expect unsat\n", "", "missing '@expect sat|unsat'"),
    ("lemma_runup.smt2.in", "(assert (not (lemma_runup v vs a t H)))",
     "(assert (< 0 t))\n(assert (not (lemma_runup v vs a t H)))", "must be '@expect unsat'"),
    ("lemmas.smt2.in", "(<= (* 2 b_real db) (* v1 v1)))", "(<= (* 2 b_real db) (* v1 V_MAX)))",
     "refers to V_MAX"),
])
def test_template_errors_name_file_and_reason(cli, tmp_path, file, old, new, fragment):
    pr = _copy(tmp_path, PROOFS)
    edit(pr / "br" / file, old, new)
    res = cli("proofs", "--spec", SPEC, "--proofs", pr, "--out", tmp_path / "out")
    assert res.rc == 1
    assert "proofs/br/" in res.err and fragment in res.err, res.err


def test_a_lemma_changed_in_one_place_is_unproved(cli, tmp_path):
    """A user of a lemma whose definition differs from the proved one is refused."""
    pr = _copy(tmp_path, PROOFS)
    lem = pr / "br" / "lemmas.smt2.in"
    text = lem.read_text()
    (pr / "br" / "lemmas_weak.smt2.in").write_text(
        text.replace("(<= db D)))", "(<= db (+ D 1.0))))"))
    edit(pr / "br" / "br_a_invariant.smt2.in", "{{include lemmas.smt2.in}}",
          "{{include lemmas_weak.smt2.in}}")
    res = cli("proofs", "--spec", SPEC, "--proofs", pr, "--out", tmp_path / "out")
    assert res.rc == 1 and "uses lemma_braking but no obligation proves this definition" \
        in res.err


# ------------------------------------------------------------------------ trace ----
def _trace(tmp_path, data):
    results = tmp_path / "results"
    (results / "proofs").mkdir(parents=True)
    if data is not None:
        (results / "proofs" / "br.json").write_text(json.dumps(data))
    t, report = build_trace(SPEC, REPO, results, allow_missing=True)
    errors = [str(e) for e in report.errors if "proofs" in str(e)]
    return t, errors


def test_trace_reads_obligation_tags_and_expected_verdicts(tmp_path):
    t, errors = _trace(tmp_path, None)
    assert errors == []
    links = {r["id"]: r["links"]["proof"] for r in t["requirements"]}
    assert {"file": "proofs/br/br_b_moving_block.smt2.in",
            "obligation": "BR_b_moving_block"} in links["REQ-BR-015"]
    assert {"file": "proofs/br/br_c_d2_buffer.smt2.in",
            "obligation": "BR_c_d2_buffer"} in links["REQ-BR-016"]
    assert {"file": "proofs/br/br_a_stop.smt2.in",
            "obligation": "BR_a_stop"} in links["REQ-BR-014"]
    assert {"file": "proofs/br/br_a2_rounding.smt2.in",
            "obligation": "BR_a2_rounding"} in links["REQ-BR-008"]
    from railproof_testgen.trace import Tracer
    tr = Tracer(SPEC, REPO, tmp_path / "none", True)
    tr.run()
    assert tr.proof_obligations["BR_a_wrong_noerror"]["expect"] == "sat"
    assert tr.proof_obligations["BR_a_stop"]["expect"] == "unsat"
    assert tr.proof_obligations["BR_a_stop"]["file"] == "proofs/br/br_a_stop.smt2.in"


def test_trace_accepts_the_replay_and_rejects_tampered_results(tmp_path, replay):
    _out, data = replay
    _t, errors = _trace(tmp_path / "ok", data)
    assert errors == []

    bad = copy.deepcopy(data)
    row = next(r for r in bad["obligations"] if r["name"] == "BR_a_stop.dmu2_d4")
    row["cvc5"]["verdict"] = "sat"
    row["meets_target"] = False
    bad["verdict"] = "fail"
    _t, errors = _trace(tmp_path / "flip", bad)
    assert any("BR_a_stop.dmu2_d4: cvc5 verdict 'sat', expected unsat" in e for e in errors)
    assert any("proof replay failed" in e for e in errors)

    bad = copy.deepcopy(data)
    bad["obligations"] = [r for r in bad["obligations"] if r["obligation"] != "BR_c_d2_buffer"]
    _t, errors = _trace(tmp_path / "missing", bad)
    assert any("@obligation BR_c_d2_buffer" in e and "no replay result" in e for e in errors)

    bad = copy.deepcopy(data)
    bad["obligations"][0] = dict(bad["obligations"][0], obligation="BR_gone", name="BR_gone")
    _t, errors = _trace(tmp_path / "stale", bad)
    assert any("stale result: no @obligation BR_gone" in e for e in errors)
