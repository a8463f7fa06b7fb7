"""Tests of the SPIN runner and the vector derivation (railproof_testgen.spin / .vectors)."""
import shutil
from pathlib import Path

import pytest

from railproof_testgen import spin, vectors
from railproof_testgen.errors import PipelineError, SpecError

FIX = Path(__file__).parent / "fixtures" / "spin"
REPO = Path(__file__).resolve().parents[2]
needs_spin = pytest.mark.skipif(shutil.which("spin") is None or shutil.which("cc") is None,
                                reason="spin and a C compiler are needed")


def test_annotations_of_the_telegram_model():
    ann = spin.parse_annotations(REPO / "models" / "telegram.pml")
    names = {p.name for p in ann.properties}
    assert "REQ_TG_009_turnaround" in names
    assert all(p.requirements for p in ann.properties)
    assert len(ann.goals) == 20 and [g.number for g in ann.goals] == list(range(20))
    assert {m.name for m in ann.mutants} >= {"MUTANT_SEQ_WIDTH_8", "MUTANT_NO_AUTH_CHECK"}
    assert "R_GUARANTEE_ECHO_AGE" in ann.asserts
    healthy = [p for p in ann.properties if p.config == "HEALTHY"]
    assert [p.name for p in healthy] == ["REQ_TG_016_availability"]


def test_mutant_naming_an_unknown_property_is_rejected(tmp_path):
    m = tmp_path / "m.pml"
    m.write_text("// @property P REQ-TG-001 : p\nltl P { [] true }\n// @mutant MX violates Q : q\n")
    with pytest.raises(SpecError, match="unknown property Q"):
        spin.parse_annotations(m)


def test_duplicate_goal_is_rejected(tmp_path):
    m = tmp_path / "m.pml"
    m.write_text("// @property P REQ-TG-001 : p\n// @goal 1 REQ-TG-001 : a\n// @goal 1 REQ-TG-001 : b\n")
    with pytest.raises(SpecError, match="duplicate @goal 1"):
        spin.parse_annotations(m)


def test_parse_pan_flags_truncated_searches_as_incomplete():
    out = ("error: max search depth too small\nFull statespace search for:\n"
           "State-vector 68 byte, depth reached 999999, errors: 0\n  11477978 states, stored\n"
           "pan: elapsed time 22.4 seconds\n")
    res = spin.parse_pan(out)
    assert res["errors"] == 0 and res["states_stored"] == 11477978 and res["depth"] == 999999
    assert res["incomplete"] == ["search depth bound reached"]


def test_parse_events_and_steps_for_both_roles():
    text = "\n".join([
        "  @IN tick", "  @OUT tx seq=7 echo=255 link=0 eb=1 abnormal=1",
        "  @IN rx seq=6 echo=7 mode=4", "  @OUT rx verdict=2 gap=0 link=0 eb=1 abnormal=1",
        "  @IN rx seq=6 echo=7 mode=0", "  @OUT rx verdict=0 gap=0 link=1 eb=0 abnormal=0",
        "  @IN tick"])  # an input cut off by the end of a trail is dropped
    ev = vectors.parse_events(text)
    assert len(ev) == 3
    ids = {"ground_id": 1, "train_id": 42, "other_train_id": 43}
    g = vectors.to_steps(ev, "ground", ids)
    t = vectors.to_steps(ev, "train", ids)
    assert g[0]["out"] == {"tx": {"seq": 7, "echo": None}, "link": "NONE", "tracking": "ABNORMAL"}
    assert t[0]["out"] == {"tx": {"seq": 7, "echo": None}, "link": "NONE", "eb": True}
    # misaddressed: from another train towards the ground, towards another train from the ground
    assert g[1]["in"]["tg"]["src"] == 43 and g[1]["in"]["tg"]["type"] == "POSITION"
    assert t[1]["in"]["tg"]["dst"] == 43 and t[1]["in"]["tg"]["type"] == "CONTROL"
    assert g[1]["out"]["verdict"] == "REJ_ADDRESS"
    assert t[2]["out"] == {"verdict": "ACCEPT", "gap": 0, "link": "UP", "eb": False}
    assert vectors.observed_requirements(ev) == {"REQ-TG-003", "REQ-TG-008"}


def test_output_without_input_is_an_error():
    with pytest.raises(PipelineError, match="without @IN"):
        vectors.parse_events("@OUT rx verdict=0 gap=0 link=1 eb=0 abnormal=0")


@needs_spin
def test_verify_fails_with_the_counterexample_on_a_violated_property(tmp_path):
    with pytest.raises(PipelineError) as exc:
        spin.verify(FIX / "tiny.pml", FIX, tmp_path / "work", tmp_path / "out.json", jobs=1)
    msg = str(exc.value)
    assert "P_BELOW (REQ-TG-008) [default] violated" in msg
    assert "@OUT tx seq=" in msg  # the replayed counterexample is shown
    import json
    res = json.loads((tmp_path / "out.json").read_text())
    assert res["properties"][0]["verdict"] == "violated"


@needs_spin
def test_verify_passes_when_the_property_holds(tmp_path):
    params = tmp_path / "params"
    params.mkdir()
    (params / "tiny_params.pml").write_text("#define MODEL_WRAP 4\n#define MODEL_LIMIT 5\n")
    res = spin.verify(FIX / "tiny.pml", params, tmp_path / "work", tmp_path / "out.json", jobs=1)
    p = res["properties"][0]
    assert p["verdict"] == "verified" and p["errors"] == 0 and p["states_stored"] > 0
    assert res["bounds"] == {"wrap": 4, "limit": 5}


def test_run_retries_text_file_busy_and_raises_other_errors(monkeypatch):
    """A freshly linked ./pan can be 'text file busy' for a moment under load: retried; any
    other OSError is not."""
    import errno as _errno
    calls = {"n": 0}
    real = spin.subprocess.run

    def busy_twice(*a, **k):
        calls["n"] += 1
        if calls["n"] < 3:
            raise OSError(_errno.ETXTBSY, "Text file busy")
        return real(*a, **k)

    monkeypatch.setattr(spin.subprocess, "run", busy_twice)
    assert spin._run(["true"], ".").returncode == 0 and calls["n"] == 3

    def missing(*a, **k):
        raise OSError(_errno.ENOENT, "No such file")

    monkeypatch.setattr(spin.subprocess, "run", missing)
    with pytest.raises(OSError):
        spin._run(["true"], ".")


TWO_INVARIANTS = """/* two invariants of one counter (tests of the combined search) */
#include "two_params.pml"
byte x;
bit v_over, v_big;
active proctype env() {
  do
  :: d_step { printf("@IN tick\\n"); x = (x + 1) % MODEL_WRAP;
              printf("@OUT tx seq=%d echo=255 link=0 eb=1 abnormal=1\\n", x);
              if :: x >= MODEL_LIMIT -> v_over = 1 :: else -> skip fi;
              if :: x >= 7 -> v_big = 1 :: else -> skip fi }
  od
}
// @property P_BELOW REQ-TG-008 : the counter stays below MODEL_LIMIT
ltl P_BELOW { [] !v_over }
// @property P_SMALL REQ-TG-008 : the counter stays below 7
ltl P_SMALL { [] (x < 7 && !v_big) }
"""


def _two(tmp_path, wrap):
    model = tmp_path / "two.pml"
    model.write_text(TWO_INVARIANTS)
    params = tmp_path / "params"
    params.mkdir()
    (params / "two_params.pml").write_text(f"#define MODEL_WRAP {wrap}\n#define MODEL_LIMIT 5\n")
    return model, params


def test_invariant_claims_and_their_conjunction():
    claims = spin.invariant_claims(TWO_INVARIANTS + "ltl LIVE { <> x == 3 }\n")
    assert claims == {"P_BELOW": "!v_over", "P_SMALL": "(x < 7 && !v_big)"}
    assert spin.combined_claim(list(claims.values())) == \
        "ltl railproof_all { [] ((!v_over) && ((x < 7 && !v_big))) }\n"


@needs_spin
def test_properties_of_a_configuration_are_verified_in_one_search(tmp_path):
    import subprocess
    model, params = _two(tmp_path, wrap=4)
    res = spin.verify(model, params, tmp_path / "work", tmp_path / "out.json", jobs=1)
    below, small = res["properties"]
    assert below["verdict"] == small["verdict"] == "verified"
    assert below["verified_with"] == ["P_SMALL"] and small["verified_with"] == ["P_BELOW"]
    assert below["command"] == small["command"] and below["command"].endswith("./pan -N railproof_all")
    assert below["states_stored"] == small["states_stored"] > 0
    # the recorded command replays the combined search from the model alone
    replay = tmp_path / "replay"
    replay.mkdir()
    shutil.copy2(model, replay)
    shutil.copy2(params / "two_params.pml", replay)
    r = subprocess.run(["bash", "-c", below["command"]], cwd=replay, capture_output=True, text=True)
    assert r.returncode == 0 and "errors: 0" in r.stdout, r.stdout + r.stderr


@needs_spin
def test_a_violation_found_together_is_reported_against_its_property(tmp_path):
    model, params = _two(tmp_path, wrap=6)  # the counter reaches 5: P_BELOW fails, P_SMALL holds
    with pytest.raises(PipelineError) as exc:
        spin.verify(model, params, tmp_path / "work", tmp_path / "out.json", jobs=2)
    assert "P_BELOW (REQ-TG-008) [default] violated" in str(exc.value)
    assert "P_SMALL" not in str(exc.value)
    import json
    below, small = json.loads((tmp_path / "out.json").read_text())["properties"]
    assert below["verdict"] == "violated" and "@OUT tx seq=5" in below["counterexample"]
    assert small["verdict"] == "verified" and small["command"].endswith("./pan -N P_SMALL")
    assert "verified_with" not in small
