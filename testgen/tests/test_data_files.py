"""The hand-written JSON data of the simulators (spec/scenarios for line_sim, spec/wheelrail
for wheelrail_sim and the odometry study): validate applies their schemas and what the
schemas cannot say (the line, running line, stations and routes a scenario names; the
requirements a wheel-rail scenario names; the file name); every finding is
'file: entry: reason' and fails the build step that validates spec/. Files written by hand
elsewhere are checked the same way with --data."""
from __future__ import annotations

import json
import shutil

import pytest

from conftest import REPO

SCENARIO = "scenarios/d1_faults.json"
WHEELRAIL = "wheelrail/micro_slips.json"


@pytest.fixture
def data_spec(tmp_path):
    """data_spec(path, edit) -> a copy of spec/ whose JSON file `path` is changed by
    edit(obj) (a function changing the loaded object) or replaced by edit (a text)."""

    def make(path, edit):
        spec = tmp_path / "spec"
        if spec.exists():
            shutil.rmtree(spec)
        shutil.copytree(REPO / "spec", spec)
        if isinstance(edit, str):
            (spec / path).write_text(edit, encoding="utf-8")
        else:
            obj = json.loads((spec / path).read_text(encoding="utf-8"))
            edit(obj)
            (spec / path).write_text(json.dumps(obj, indent=1), encoding="utf-8")
        return spec

    return make


def _siding(obj, **kw):
    obj["faults"] = [{"type": "siding_request", "from_s": 1, "to_s": 2, **kw}]


def _set(key, value):
    return lambda obj: obj.__setitem__(key, value)


_BASE = (REPO / "spec" / SCENARIO).read_text(encoding="utf-8")


@pytest.mark.parametrize("edit, entry, reason", [
    (_set("line", "d9_line"), "line", "unknown line 'd9_line' (no lines/d9_line.yaml)"),
    (_set("running_line", "left"), "running_line",
     "unknown running line 'left' on line d1_test_line (has: up, down)"),
    (lambda o: o["trains"][0]["stops"][0].__setitem__("station", "Q"), "trains[2].stops[0]",
     "station: unknown station 'Q' on running line up (has: A, B, C, D)"),
    (lambda o: _siding(o, route=7), "faults[0]", "route: unknown route 7 on running line up"),
    (_set("name", "other"), "name", "'other' must equal the file name 'd1_faults'"),
    (_set("trainz", 1), "-", "Additional properties are not allowed ('trainz' was unexpected)"),
    (lambda o: o["trains"][0].__setitem__("id", 1), "trains[1]", "id: 1 should not be valid"),
    (lambda o: o["channel"].__setitem__("loss_probability", 1.5), "channel",
     "loss_probability: 1.5 is greater than the maximum of 1"),
    (_BASE.replace('"seed": 11', '"seed": NaN'), "-", "malformed JSON: NaN is not a number"),
    (_BASE.replace('"duration_s": 1500', '"duration_s": 1e400'), "-",
     "malformed JSON: number 1e400 is out of range"),
    (_BASE.replace('"seed": 11', '"seed": 11, "seed": 12'), "-",
     "malformed JSON: duplicate key 'seed'"),
])
# @verifies REQ-MB-020
def test_scenario_rules(data_spec, cli, edit, entry, reason):
    r = cli("validate", "--spec", data_spec(SCENARIO, edit))
    assert r.rc == 1
    assert r.has(SCENARIO, entry, reason), r.err


@pytest.mark.parametrize("edit, entry, reason", [
    (lambda o: o["requirements"].append("REQ-RA-999"), "micro_slips",
     "unknown requirement REQ-RA-999"),
    (_set("requirements", ["RA-1"]), "requirements", "'RA-1' does not match"),
    (_set("duraton_s", 5), "-", "('duraton_s' was unexpected)"),
    (_set("name", "other"), "name", "must equal the file name 'micro_slips'"),
    (lambda o: o["vertical"]["gradients"][0].__setitem__("permille", 36),
     "vertical", "gradients.0.permille: 36 is greater than the maximum of 35"),
])
def test_wheelrail_rules(data_spec, cli, edit, entry, reason):
    r = cli("validate", "--spec", data_spec(WHEELRAIL, edit))
    assert r.rc == 1
    assert r.has(WHEELRAIL, entry, reason), r.err


def test_a_siding_request_needs_a_siding_route(data_spec, cli):
    spec = data_spec(SCENARIO, _siding)
    line = spec / "lines/d1_test_line.yaml"
    text = line.read_text(encoding="utf-8")
    old = 'position: reverse, automatic: false, note: "C arrival over the crossover"'
    assert old in text
    line.write_text(text.replace(old, old.replace("false", "true")), encoding="utf-8")
    r = cli("validate", "--spec", spec)
    assert r.rc == 1
    assert r.has(SCENARIO, "faults[0]", "running line up has no siding (reverse, non-automatic) "
                                        "route"), r.err


def test_a_bad_data_file_fails_the_build_step(data_spec, cli, tmp_path):
    """gen-params validates spec/ before it writes the headers (the build's first step)."""
    spec = data_spec(SCENARIO, _set("line", "d9_line"))
    r = cli("gen-params", "--spec", spec, "--out", tmp_path / "gen")
    assert r.rc == 1
    assert f"{SCENARIO}: line: unknown line 'd9_line'" in r.err
    assert not (tmp_path / "gen").exists()


def test_hand_written_files_are_checked_with_data(cli, tmp_path):
    obj = json.loads(_BASE)
    mine = tmp_path / "my_run.json"  # any file name
    mine.write_text(json.dumps(obj), encoding="utf-8")
    r = cli("validate", "--spec", REPO / "spec", "--data", mine,
            "--data", REPO / "spec" / WHEELRAIL)
    assert r.rc == 0, r.err
    typo, left = tmp_path / "typo.json", tmp_path / "left.json"
    left.write_text(json.dumps(dict(obj, running_line="left")), encoding="utf-8")
    obj["trains"][0]["stops"][0]["dwel_s"] = 30
    typo.write_text(json.dumps(obj), encoding="utf-8")
    other = tmp_path / "other.json"
    other.write_text('{"schema": "railproof/line-json/1"}', encoding="utf-8")
    r = cli("validate", "--spec", REPO / "spec", "--data", typo, "--data", left,
            "--data", other)
    assert r.rc == 1
    assert r.has("typo.json", "trains[2].stops[0]", "'dwel_s' was unexpected"), r.err
    assert r.has("left.json", "running_line", "unknown running line 'left'"), r.err
    assert r.has("other.json", "schema", "not one of railproof/scenario/1")
