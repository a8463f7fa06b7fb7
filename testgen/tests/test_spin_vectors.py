"""Tests of the SPIN runner and the generic vector engine (railproof_testgen.spin, .vectors) on
the tiny fixture models of fixtures/spin: tiny.pml (one counter, verification) and counters.pml
(two interleaved counters, a few hundred states: goals at several depths, one reachable only in
the variant WIDE, one never, one in configuration FAST). The fixture's part of vector
generation is the class Counters below, its schema and justification fixtures/spin/spec. The
vector sets of a build, read from RAILPROOF_RESULTS_DIR, are checked at the end."""
import hashlib
import json
import shutil
import subprocess
from pathlib import Path

import pytest

from railproof_testgen import registry, spin, vectors
from railproof_testgen.errors import PipelineError, SpecError
from railproof_testgen.files import write_atomic
from railproof_testgen.vectors import Configuration
from vector_results import check_vector_set, vector_set

FIX = Path(__file__).parent / "fixtures" / "spin"
REPO = Path(__file__).resolve().parents[2]
COUNTERS = FIX / "counters.pml"
needs_spin = pytest.mark.skipif(shutil.which("spin") is None or shutil.which("cc") is None,
                                reason="spin and a C compiler are needed")


# ---- annotations and pan output ----------------------------------------------------------------
def test_annotations_of_the_fixture():
    ann = spin.parse_annotations(COUNTERS)
    assert [g.number for g in ann.goals] == list(range(6))
    assert [g.config for g in ann.goals] == [None] * 5 + ["FAST"]
    assert ann.goals[1].requirements == ["REQ-TG-001", "REQ-TG-003"]
    assert ann.goals[2].label == "boundary: a at the limit"
    assert [(p.name, p.configs) for p in ann.properties] == [("P_LIMIT", [None]), ("P_STEPS", ["FAST"])]
    assert [(v.define, v.parameter, v.bound) for v in ann.variants] == [("WIDE", "limit", "wide_limit")]


def test_environment_variant_without_a_parameter(tmp_path):
    m = tmp_path / "m.pml"
    m.write_text("// @property P REQ-TG-001 : p\nltl P { [] true }\n"
                 "// @variant NARROW : a narrower environment\n// @variant WIDE limit=wide_limit : wider\n")
    ann = spin.parse_annotations(m)
    assert [(v.define, v.parameter, v.bound, v.text) for v in ann.variants] == [
        ("NARROW", None, None, "a narrower environment"), ("WIDE", "limit", "wide_limit", "wider")]


def test_walk_only_configuration_is_neither_verified_nor_a_variant(tmp_path):
    m = tmp_path / "m.pml"
    m.write_text("// @property P REQ-TG-001 : p\nltl P { [] true }\n"
                 "// @walks UNIT : the unit's environment at its own times\n// @variant NARROW : narrower\n")
    ann = spin.parse_annotations(m)
    assert ann.walk_only == [("UNIT", "the unit's environment at its own times")]
    assert [v.define for v in ann.variants] == ["NARROW"]  # only variants are verified and searched
    from railproof_testgen.registry import model_configurations
    assert model_configurations(m) == ["default", "NARROW", "UNIT"]


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


# ---- verification ------------------------------------------------------------------------------
@needs_spin
def test_verify_fails_with_the_counterexample_on_a_violated_property(tmp_path):
    with pytest.raises(PipelineError) as exc:
        spin.verify(FIX / "tiny.pml", FIX, tmp_path / "work", tmp_path / "out.json", jobs=1)
    msg = str(exc.value)
    assert "P_BELOW (REQ-TG-008) [default] violated" in msg
    assert "@OUT tx seq=" in msg  # the replayed counterexample is shown
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
    below, small = json.loads((tmp_path / "out.json").read_text())["properties"]
    assert below["verdict"] == "violated" and "@OUT tx seq=5" in below["counterexample"]
    assert small["verdict"] == "verified" and small["command"].endswith("./pan -N P_SMALL")
    assert "verified_with" not in small


@needs_spin
def test_verify_checks_every_configuration_and_variant(tmp_path):
    res = spin.verify(COUNTERS, _params(tmp_path), tmp_path / "work", tmp_path / "out.json", jobs=2)
    runs = {(p["name"], p["configuration"]): p for p in res["properties"]}
    # P_LIMIT in the default configuration and in the variant WIDE, P_STEPS in FAST
    assert set(runs) == {("P_LIMIT", "default"), ("P_LIMIT", "WIDE"), ("P_STEPS", "FAST")}
    assert all(p["verdict"] == "verified" and p["states_stored"] > 0 for p in runs.values())
    assert runs[("P_LIMIT", "WIDE")]["states_stored"] > runs[("P_LIMIT", "default")]["states_stored"]


# ---- the trap search ---------------------------------------------------------------------------
def _params(tmp_path):
    params = tmp_path / "params"
    params.mkdir(exist_ok=True)
    shutil.copy2(FIX / "counters_params.pml", params)
    return params


def _io(text):
    return [ln.strip() for ln in text.splitlines() if "@IN" in ln or "@OUT" in ln]


@needs_spin
@pytest.mark.parametrize("config", [None, "WIDE", "FAST"])
def test_one_search_gives_each_goal_the_run_of_its_own_trap_property(tmp_path, config):
    """The technique's reference: every goal K searched alone with `ltl goalK { [] !g[K] }`
    (pan -DBFS stops at its first violation). The one search of all goals must give each goal
    the same run, and an unreachable goal the same complete search."""
    params = _params(tmp_path)
    ann = spin.parse_annotations(COUNTERS)
    numbers = [g.number for g in ann.goals]
    defines = ["TRAPS"] + ([config] if config else [])
    s = spin.search_goals(COUNTERS, params, tmp_path / "search", defines, numbers)
    ref = spin.prepare(COUNTERS, params, tmp_path / "ref", defines,
                       texts={spin.goals_file(COUNTERS): "".join(f"ltl goal{k} {{ [] !g[{k}] }}\n" for k in numbers)})
    unreachable = 0
    for k in numbers:
        r = spin._run(["./pan", "-N", f"goal{k}"], ref)
        res = spin.parse_pan(r.stdout)
        if not res["errors"]:
            unreachable += 1
            assert k not in s.trails
            assert not res["incomplete"] and res["states_stored"] == s.res["states_stored"]
            continue
        own = spin._run(["spin", *[f"-D{d}" for d in defines], "-t", COUNTERS.name], ref).stdout
        (ref / f"{COUNTERS.name}.trail").unlink()
        assert _io(s.replay(s.trails[k], tmp_path / f"replay{k}")) == _io(own), f"goal {k}"
    assert unreachable == {None: 2, "WIDE": 1, "FAST": 2}[config]


@needs_spin
def test_a_model_assertion_in_the_trap_search_is_an_error(tmp_path):
    with pytest.raises(PipelineError, match=r"violated outside its goals: assertion violated"):
        spin.search_goals(COUNTERS, _params(tmp_path), tmp_path / "search", ["TRAPS", "BROKEN"], [0, 1, 2])


def test_a_model_without_the_goals_include_is_named(tmp_path):
    model = tmp_path / "counters.pml"
    model.write_text(COUNTERS.read_text().replace('#include "counters_goals.pml"', ""))
    with pytest.raises(SpecError, match=r'counters.pml: TRAPS: the model does not #include "counters_goals.pml"'):
        spin.search_goals(model, _params(tmp_path), tmp_path / "search", ["TRAPS"], [0])


def test_an_incomplete_search_does_not_make_goals_unreachable(tmp_path, monkeypatch):
    monkeypatch.setattr(spin, "prepare", lambda *a, **k: tmp_path)
    out = ("error: max search depth too small\nFull statespace search for:\n"
           "State-vector 36 byte, depth reached 9999, errors: 0\n  905 states, stored\n")
    monkeypatch.setattr(spin, "_run", lambda *a, **k: subprocess.CompletedProcess(a, 0, out, ""))
    with pytest.raises(PipelineError, match=r"\[TRAPS\]: trap search incomplete \(search depth bound "
                                            r"reached\); goals not reached: G0, G1"):
        spin.search_goals(COUNTERS, tmp_path, tmp_path, ["TRAPS"], [0, 1], pan_flags=[])
    monkeypatch.setattr(spin, "_run", lambda *a, **k: subprocess.CompletedProcess(a, 0, "Segmentation fault", ""))
    with pytest.raises(PipelineError, match="unexpected output of pan"):
        spin.search_goals(COUNTERS, tmp_path, tmp_path, ["TRAPS"], [0, 1], pan_flags=[])


# ---- the engine, with the fixture's part ---------------------------------------------------------
class Counters(vectors.Part):
    prefix = "CT"
    configurations = (Configuration(None, walks=1),
                      Configuration("WIDE", suffix=".wide", tag="WIDE-"),
                      Configuration("FAST", suffix=".fast", tag="FAST-", walks=4, walk_evidence=True))
    variant_search = "unreachable"
    walk_defines = ()
    walk_events = "steps"

    def bounds(self, model, params_pml):
        return vectors.model_bounds(params_pml, ("limit", "wide_limit", "steps"))

    def parse_events(self, text):
        events, pending = [], None
        for line in _io(text):
            if line.startswith("@IN "):
                pending = line[4:]
            elif pending is None:
                raise PipelineError(f"@OUT without @IN: {line}")
            else:
                a, b = (int(x.split("=")[1]) for x in line[5:].split())
                events.append((pending, a, b))
                pending = None
        return events

    def to_steps(self, events, bounds, define):
        return [{"in": {"proc": p}, "out": {"a": a, "b": b}} for p, a, b in events]

    def observed_requirements(self, steps):
        """Every run shows the counting (REQ-TG-001), b catching up with a REQ-TG-003."""
        caught_up = any(s["out"]["a"] == s["out"]["b"] > 0 for s in steps)
        return {"REQ-TG-001"} | ({"REQ-TG-003"} if caught_up else set())

    def header(self, target, define):
        b = target.bounds
        return target.header(configuration=self.configuration(define).name,
                             parameters={"limit": b["wide_limit" if define == "WIDE" else "limit"],
                                         "steps": b["steps"]})


def _generate(tmp_path, part=None, spec=FIX / "spec", walks=3, out=None):
    out = out or tmp_path / "out"
    return vectors.generate(COUNTERS, _params(tmp_path), spec, tmp_path / "work", out, walks=walks, jobs=2,
                            part=("ct", part or Counters())), out


def _lines(path):
    return [json.loads(ln) for ln in path.read_text(encoding="utf-8").splitlines()]


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    if shutil.which("spin") is None or shutil.which("cc") is None:
        pytest.skip("spin and a C compiler are needed")
    tmp = tmp_path_factory.mktemp("ct")
    (tmp / "out").mkdir()
    (tmp / "out" / "counters.old.jsonl").write_text("{}\n")  # a file of an earlier configuration
    (tmp / "out" / "other.jsonl").write_text("{}\n")         # another model's
    cov, out = _generate(tmp)
    return cov, out, {p.name: _lines(p) for p in out.glob("counters*.jsonl")}


@needs_spin
def test_files_of_every_configuration_with_vectors(generated):
    cov, out, files = generated
    assert sorted(files) == ["counters.fast.jsonl", "counters.jsonl", "counters.wide.jsonl"]
    assert (out / "other.jsonl").exists()  # only the model's own earlier files are removed
    assert cov["files"] == {n: len(lines) - 1 for n, lines in files.items()}
    assert json.loads((out / "counters.coverage.json").read_text()) == cov
    for name, lines in files.items():
        h = lines[0]
        assert h["kind"] == "header" and h["model"] == "models/counters.pml"
        assert h["model_sha256"] == spin.sha256_file(COUNTERS) and h["generator"].startswith("railproof_testgen")
    assert files["counters.wide.jsonl"][0]["configuration"] == "WIDE"
    assert files["counters.wide.jsonl"][0]["parameters"] == {"limit": 4, "steps": 8}
    assert not list(out.glob("*.tmp"))
    for name, lines in files.items():  # each file whole: its header counts and digests its vector lines
        text = (out / name).read_text(encoding="utf-8")
        assert vectors.check_seal(text, name) == lines[0]
        assert lines[0]["schema_version"] == vectors.SCHEMA_VERSION == 2
        assert lines[0]["vector_count"] == len(lines) - 1
        assert lines[0]["vectors_sha256"] == hashlib.sha256(text.split("\n", 1)[1].encode()).hexdigest()


@needs_spin
def test_goal_coverage_with_variant_and_justification(generated):
    cov, _out, files = generated
    goals = {g["id"]: g for g in cov["goals"]}
    assert [g["id"] for g in cov["goals"]] == [f"G{k}" for k in range(6)]
    assert cov["labelled"] == 6 and cov["reached"] == 4 and cov["unreachable_justified"] == 2
    assert goals["G2"]["vectors"] == ["CT-BOUNDARY-G2"] and goals["G0"]["vectors"] == ["CT-TRAP-G0"]
    assert goals["G5"]["configuration"] == "FAST" and goals["G5"]["vectors"] == ["CT-TRAP-FAST-G5"]
    # unreachable in the default configuration, reached in the variant: its own file
    g3 = goals["G3"]
    assert g3["status"] == "unreachable" and g3["justification"] == "UR-TG-901" and g3["states_searched"] > 0
    assert g3["variant"] == "WIDE" and g3["variant_vectors"] == ["CT-TRAP-WIDE-G3"]
    assert [v["id"] for v in files["counters.wide.jsonl"][1:]] == ["CT-TRAP-WIDE-G3"]
    # unreachable everywhere, justified; only the goals unreachable at home are searched again
    g4 = goals["G4"]
    assert g4["justification"] == "UR-TG-902" and g4["states_searched"] == g3["states_searched"]
    assert "variant" not in g4 and "variant" not in goals["G0"]
    assert all(g["justification"] is None and g["states_searched"] is None
               for g in cov["goals"] if g["status"] == "reached")


@needs_spin
def test_trap_vectors_are_the_replayed_runs(generated):
    _cov, _out, files = generated
    vecs = {v["id"]: v for lines in files.values() for v in lines[1:]}
    g0, g1 = vecs["CT-TRAP-G0"], vecs["CT-TRAP-G1"]
    assert g0["goal"] == "G0" and g0["kind"] == "trap" and g0["seed"] is None
    assert [s["in"]["proc"] for s in g0["steps"]] == ["up", "up"] and g0["steps"][-1]["out"]["a"] == 2
    assert g1["requirements"] == ["REQ-TG-001", "REQ-TG-003"]
    assert vecs["CT-TRAP-G0"]["requirements"] == ["REQ-TG-001"]  # the goal's own and what the run shows
    assert vecs["CT-BOUNDARY-G2"]["requirements"] == ["REQ-TG-001", "REQ-TG-004"]
    last = g1["steps"][-1]
    assert last["in"]["proc"] == "down" and last["out"]["a"] == last["out"]["b"] > 0
    assert vecs["CT-TRAP-WIDE-G3"]["steps"][-1]["out"]["a"] == 4
    assert vecs["CT-BOUNDARY-G2"]["kind"] == "boundary"


@needs_spin
def test_random_walks_per_configuration(generated):
    _cov, _out, files = generated
    main = files["counters.jsonl"][1:]
    # boundary, trap, then random vectors, each by number
    assert [v["id"] for v in main] == ["CT-BOUNDARY-G2", "CT-TRAP-G0", "CT-TRAP-G1",
                                       "CT-RANDOM-S1", "CT-RANDOM-S2", "CT-RANDOM-S3"]
    walks = [v for v in main if v["kind"] == "random"]
    assert [v["seed"] for v in walks] == [1, 2, 3] and all(v["goal"] is None for v in walks)
    assert all(len(v["steps"]) == 8 for v in walks)  # Part.walk_events: MODEL_STEPS
    assert len({json.dumps(v["steps"]) for v in walks}) > 1  # the seeds give different runs
    fast = [v for v in files["counters.fast.jsonl"][1:] if v["kind"] == "random"]
    assert [v["id"] for v in fast] == ["CT-RANDOM-FAST-S1"]  # walks // 4, at least one
    assert "REQ-TG-005" in fast[0]["requirements"]  # the property verified in FAST (walk_evidence)
    assert all("REQ-TG-005" not in v["requirements"] for v in walks)


@needs_spin
def test_a_random_walk_is_reproduced_by_its_seed(tmp_path):
    gen = vectors.Generation("ct", Counters(), COUNTERS, _params(tmp_path), FIX / "spec", tmp_path / "w",
                             tmp_path / "o", walks=3, walk_steps=None, jobs=1)
    assert gen.walk((None, 2)) == gen.walk((None, 2))
    assert gen.walk((None, 2))[1] != gen.walk((None, 3))[1]
    assert len(gen.walk(("FAST", 1))[1]) == 8


RUN = [("up", 1, 0), ("up", 2, 0)]


def _canned(monkeypatch):
    """The engine without the trap searches: G3 and G4 unreachable, the other goals reached by
    the run RUN (their vectors and coverage come from the engine as after a search)."""
    def search_plan(self):
        out = {(g.number, g.config): vectors.Outcome("reached", RUN, None) for g in self.ann.goals}
        out.update({(k, None): vectors.Outcome("unreachable", None, 1010) for k in (3, 4)})
        return out

    monkeypatch.setattr(vectors.Generation, "search_plan", search_plan)


@pytest.mark.parametrize("policy", ["all", "unreachable"])
def test_default_goals_searched_again_in_the_variant(tmp_path, monkeypatch, policy):
    """Part.variant_search: every default-configuration goal, or those unreachable there, is
    searched again in each @variant."""
    plans = []

    def search(self, plan):
        plans.append({d: [g.gid for g in gs] for d, gs in plan.items()})
        unreachable = {3, 4}
        return {(g.number, d): vectors.Outcome("unreachable" if g.number in unreachable else "reached",
                                               None if g.number in unreachable else RUN, 7)
                for d, gs in plan.items() for g in gs}

    monkeypatch.setattr(vectors.Generation, "search", search)
    part = Counters()
    part.variant_search = policy
    gen = vectors.Generation("ct", part, COUNTERS, _params(tmp_path), FIX / "spec", tmp_path / "w", tmp_path / "o",
                             walks=1, walk_steps=None, jobs=1)
    gen.search_plan()
    home = {None: ["G0", "G1", "G2", "G3", "G4"], "FAST": ["G5"]}
    if policy == "all":
        assert plans == [{**home, "WIDE": ["G0", "G1", "G2", "G3", "G4"]}]
    else:
        assert plans == [home, {"WIDE": ["G3", "G4"]}]


def _spec_with(tmp_path, justifications):
    spec = tmp_path / f"spec{len(list(tmp_path.glob('spec*')))}"
    shutil.copytree(FIX / "spec", spec)
    (spec / "justifications" / "ct.yaml").write_text(justifications)
    return spec


@needs_spin
def test_unjustified_unreachable_goal_and_justified_reached_goal_fail(tmp_path, monkeypatch):
    _canned(monkeypatch)
    spec = _spec_with(tmp_path, "schema: railproof/justifications/1\njustifications:\n"
                                "  - {id: UR-TG-901, goal: G3, model: models/counters.pml, text: t}\n"
                                "  - {id: UR-TG-902, goal: G0, model: models/counters.pml, text: t}\n"
                                "  - {id: UR-TG-903, goal: G9, model: models/counters.pml, text: t}\n"
                                "  - {id: UR-TG-904, goal: G4, model: models/other.pml, text: t}\n")
    with pytest.raises(PipelineError) as exc:
        _generate(tmp_path, spec=spec, walks=1)
    msg = str(exc.value)
    assert "spec/justifications/ct.yaml: G4: goal unreachable in default (a above 7 (never)) and not justified" in msg
    assert "spec/justifications/ct.yaml: UR-TG-902: justifies goal G0, which is reached" in msg
    assert "UR-TG-903: justifies goal G9, which is not a goal of the model" in msg
    assert "UR-TG-901" not in msg and "UR-TG-904" not in msg  # G3 is justified; another model's
    # the files are written: the coverage shows the problem
    cov = json.loads((tmp_path / "out" / "counters.coverage.json").read_text())
    goals = {g["id"]: g for g in cov["goals"]}
    assert goals["G4"]["justification"] is None and goals["G4"]["states_searched"] == 1010
    assert goals["G3"]["justification"] == "UR-TG-901" and cov["unreachable_justified"] == 1


def test_malformed_justification_names_the_entry(tmp_path):
    spec = _spec_with(tmp_path, "schema: railproof/justifications/1\njustifications:\n  - {id: UR-TG-902}\n")
    with pytest.raises(SpecError, match=r"ct.yaml: justifications\[0\]: an entry needs 'id', 'goal' and 'model'"):
        vectors.load_justifications(spec, "ct", "models/counters.pml")
    spec = _spec_with(tmp_path, "schema: railproof/justifications/1\njustifications:\n"
                                "  - {id: UR-TG-902, goal: G4, model: models/counters.pml, text: t}\n"
                                "  - {id: UR-TG-903, goal: G4, model: models/counters.pml, text: t}\n")
    with pytest.raises(SpecError, match="UR-TG-903: goal G4 is already justified by UR-TG-902"):
        vectors.load_justifications(spec, "ct", "models/counters.pml")


@needs_spin
def test_a_schema_violation_names_the_field_and_writes_nothing(tmp_path, monkeypatch):
    _canned(monkeypatch)

    class Broken(Counters):
        def to_steps(self, events, bounds, define):
            steps = super().to_steps(events, bounds, define)
            steps[0]["out"]["a"] = "two"
            return steps

    out = tmp_path / "out"
    out.mkdir()
    (out / "counters.jsonl").write_text("earlier\n")
    with pytest.raises(PipelineError, match=r"generated counters.jsonl line 2 violates the vector schema: "
                                            r"steps/0/out/a: 'two' is not of type 'integer'$"):
        _generate(tmp_path, Broken(), walks=1, out=out)
    assert sorted(p.name for p in out.iterdir()) == ["counters.jsonl"]
    assert (out / "counters.jsonl").read_text() == "earlier\n"


def test_atomic_write_leaves_the_old_file_or_the_new_one(tmp_path, monkeypatch):
    target = tmp_path / "v.jsonl"
    target.write_text("old\n")
    write_atomic(target, "new\n", if_changed=False)
    assert target.read_text() == "new\n" and not list(tmp_path.glob("*.tmp"))

    def fail(self, other):
        raise OSError("disk full")

    monkeypatch.setattr(Path, "replace", fail)
    with pytest.raises(OSError, match="disk full"):
        write_atomic(target, "newer\n", if_changed=False)
    assert target.read_text() == "new\n" and not list(tmp_path.glob("*.tmp"))


def test_a_goal_in_a_configuration_the_part_does_not_generate(tmp_path):
    model = tmp_path / "counters.pml"
    model.write_text(COUNTERS.read_text().replace("[config FAST]", "[config SLOW]"))
    with pytest.raises(SpecError, match=r"counters.pml: G5: goal in configuration SLOW, in which capability ct "
                                        r"generates no vectors"):
        vectors.generate(model, _params(tmp_path), FIX / "spec", tmp_path / "w", tmp_path / "o",
                         part=("ct", Counters()))


def test_walk_steps_only_for_walks_bounded_by_spin(tmp_path):
    with pytest.raises(SpecError, match="--walk-steps: the model ends its random walks itself"):
        vectors.generate(COUNTERS, _params(tmp_path), FIX / "spec", tmp_path / "w", tmp_path / "o",
                         walk_steps=100, part=("ct", Counters()))


def test_a_missing_model_bound_is_named(tmp_path):
    params = tmp_path / "counters_params.pml"
    params.write_text("#define MODEL_LIMIT 3\n")
    with pytest.raises(SpecError, match=r"counters_params.pml: MODEL_STEPS: model bound missing "
                                        r"\(spec/parameters/counters.yaml model_bounds\)"):
        vectors.model_bounds(params, ("limit", "steps"))


# ---- the header's seal: a vector file is whole or rejected -------------------------------------
CT_SCHEMA = FIX / "spec" / "schemas" / "vectors_ct.schema.json"


def _ct_file(n=3):
    """The text of a fixture vector file of n vectors (the header sealed by the engine)."""
    header = {"kind": "header", "schema_version": vectors.SCHEMA_VERSION, "model": "models/counters.pml",
              "model_sha256": "0" * 64, "generator": "test", "spin_version": "test", "configuration": "default",
              "parameters": {"limit": 3, "steps": 6}}
    vecs = [{"id": f"CT-TRAP-G{k}", "requirements": ["REQ-TG-001"], "goal": f"G{k}", "kind": "trap", "seed": None,
             "steps": [{"in": {"proc": "up"}, "out": {"a": k + 1, "b": 0}}]} for k in range(n)]
    return vectors.sealed_jsonl(CT_SCHEMA, header, vecs, "ct.jsonl")


def test_the_header_states_the_count_and_the_digest_of_the_lines_as_written():
    text = _ct_file()
    head, body = text.split("\n", 1)
    header = json.loads(head)
    assert header["vector_count"] == 3 == body.count("\n")
    assert header["vectors_sha256"] == hashlib.sha256(body.encode("utf-8")).hexdigest()
    assert vectors.check_seal(text, "ct.jsonl") == header
    # no vectors: the count is 0 and the digest that of nothing
    empty = vectors.seal({"kind": "header"}, "")
    assert empty["vector_count"] == 0 and empty["vectors_sha256"] == hashlib.sha256(b"").hexdigest()


def _damaged(text, how):
    lines = text.splitlines(keepends=True)
    return {
        "cut at a line boundary": lambda: "".join(lines[:-1]),
        "a line dropped": lambda: "".join(lines[:2] + lines[3:]),
        "a line duplicated": lambda: "".join(lines[:3] + lines[2:]),
        "two lines swapped": lambda: "".join([lines[0], lines[2], lines[1], *lines[3:]]),
        "a value edited": lambda: text.replace('"a":2', '"a":5'),
        "a line added": lambda: text + lines[-1],
        "a blank line added": lambda: text + "\n",
        "cut inside a line": lambda: text[:-10],
        "the last newline lost": lambda: text[:-1],
        "line ends changed": lambda: text.replace("\n", "\r\n"),
        "an older schema version": lambda: text.replace('"schema_version":2', '"schema_version":1', 1),
        "no header": lambda: "".join(lines[1:]),
        "malformed header": lambda: "{" + text,
    }[how]()


@pytest.mark.parametrize("how, message", [
    ("cut at a line boundary", "ct.jsonl:1: the header states 3 vectors, the file has 2"),
    ("a line dropped", "ct.jsonl:1: the header states 3 vectors, the file has 2"),
    ("a line duplicated", "ct.jsonl:1: the header states 3 vectors, the file has 4"),
    ("a line added", "ct.jsonl:1: the header states 3 vectors, the file has 4"),
    ("a blank line added", "ct.jsonl:1: the header states 3 vectors, the file has 4"),
    ("two lines swapped", "ct.jsonl:1: the vector lines do not match the header's vectors_sha256 (a vector was changed)"),
    ("a value edited", "ct.jsonl:1: the vector lines do not match the header's vectors_sha256 (a vector was changed)"),
    ("line ends changed", "ct.jsonl:1: the vector lines do not match the header's vectors_sha256 (a vector was changed)"),
    ("cut inside a line", "ct.jsonl:4: the last line has no line end (file cut short?)"),
    ("the last newline lost", "ct.jsonl:4: the last line has no line end (file cut short?)"),
    ("an older schema version", "ct.jsonl:1: schema_version 1 is not supported (expected 2)"),
    ("no header", 'ct.jsonl:1: first line is not a vector header ("kind":"header")'),
    ("malformed header", "ct.jsonl:1: malformed JSON: "),
])
def test_a_damaged_file_is_rejected_by_its_seal(how, message):
    with pytest.raises(PipelineError) as info:
        vectors.check_seal(_damaged(_ct_file(), how), "ct.jsonl")
    assert str(info.value).startswith(message) and "\n" not in str(info.value)


def test_the_vector_schemas_require_the_seal():
    """Every capability's header takes the shared definition (spec/schemas/vector_header.schema.json):
    the count and the digest are required and well formed, the version is the current one and
    a key of no definition is refused."""
    from railproof_testgen.capabilities.br import PART as BR
    model = REPO / "models" / "br.pml"
    header = vectors.seal(BR.header(vectors.Target(model, spin.parse_annotations(model), {"vmax": 9, "cycles": 6},
                                                   "test"), None), "")
    shared = json.loads((REPO / "spec" / "schemas" / vectors.HEADER_SCHEMA).read_text(encoding="utf-8"))
    assert shared["$defs"]["header"]["properties"]["schema_version"] == {"const": vectors.SCHEMA_VERSION}
    for name in {c.name for c in registry.load(REPO / "spec").capabilities if c.models}:
        schema = json.loads((REPO / "spec" / "schemas" / f"vectors_{name}.schema.json").read_text(encoding="utf-8"))
        assert schema["$defs"]["header"]["$ref"] == f"{shared['$id']}#/$defs/header", name
        assert schema["$defs"]["header"]["unevaluatedProperties"] is False, name
    validator = vectors.schema_validator(REPO / "spec" / "schemas" / "vectors_br.schema.json")
    assert not list(validator.iter_errors(header))
    for what, edit in {
        "no count": lambda h: h.pop("vector_count"),
        "no digest": lambda h: h.pop("vectors_sha256"),
        "a negative count": lambda h: h.update(vector_count=-1),
        "a count as text": lambda h: h.update(vector_count="3"),
        "a digest in capitals": lambda h: h.update(vectors_sha256=h["vectors_sha256"].upper()),
        "a short digest": lambda h: h.update(vectors_sha256="e3b0c442"),
        "the former version": lambda h: h.update(schema_version=1),
        "an unknown key": lambda h: h.update(vector_total=0),
    }.items():
        broken = json.loads(json.dumps(header))
        edit(broken)
        assert list(validator.iter_errors(broken)), f"schema accepted: {what}"


# ---- the registry's capabilities ---------------------------------------------------------------
def test_every_registered_model_has_its_part():
    """The registry finds each model's part; its configuration table covers every goal's
    configuration and variant of the model, its first configuration writes the model's main
    file (the model's default one, or the one the model defines itself, as lc_gnss.pml GNSS)."""
    reg = registry.load(REPO / "spec")
    for model in reg.models:
        name, part = vectors.capability_part(REPO / "spec", REPO / model.path)
        assert name == reg.of_model(model.path).name
        ann = spin.parse_annotations(REPO / model.path)
        defines = [c.define for c in part.configurations]
        assert part.configurations[0].suffix == "" and part.configurations[0].walks >= 1, model.name
        assert len(set(defines)) == len(defines)
        assert {g.config for g in ann.goals} | {v.define for v in ann.variants} <= set(defines), model.name
        assert part.prefix == name.upper()
        if None in defines:  # the model's default configuration gets the full number of walks
            assert part.configuration(None).walks == 1
        assert (REPO / "spec" / "schemas" / f"vectors_{name}.schema.json").is_file()


def test_a_model_of_no_capability_is_an_error(tmp_path):
    with pytest.raises(SpecError, match="no capability lists the model counters.pml"):
        vectors.capability_part(REPO / "spec", COUNTERS)


# ---- the vector sets of the build (RAILPROOF_RESULTS_DIR) ---------------------------------------
@pytest.mark.parametrize("model", [m.name for m in registry.load(REPO / "spec").models])
def test_the_build_vector_set_is_valid_and_covers_every_goal(model):
    check_vector_set(vector_set(model))
