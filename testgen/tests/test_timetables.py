"""Timetables (spec/timetables, REQ-LC-017): the provided timetable validates and converts to
the JSON of the warning-time study (times in ms, a dwell per stop); each rule the schema
cannot say rejects a broken entry with 'file: entry: reason', every finding is reported,
nothing is written on error, and validate checks timetables too."""
from __future__ import annotations

import json
import shutil

import pytest

from conftest import REPO, fails_with
from railproof_testgen import timetables

TT = "timetables/d4_local_line.yaml"


@pytest.fixture
def tt_spec(tmp_path):
    """tt_spec(*edits) -> a copy of spec/ with text edits (old, new) applied to the D4
    timetable (each old text must occur exactly once)."""

    def make(*edits):
        spec = tmp_path / "spec"
        if spec.exists():
            shutil.rmtree(spec)
        shutil.copytree(REPO / "spec", spec)
        path = spec / TT
        text = path.read_text(encoding="utf-8")
        for old, new in edits:
            assert text.count(old) == 1, old
            text = text.replace(old, new)
        path.write_text(text, encoding="utf-8")
        return spec

    return make


def test_clock_times():
    assert timetables.clock_ms("06:00") == 6 * 3_600_000
    assert timetables.clock_ms("25:01:01") == (25 * 3600 + 61) * 1000


# @verifies REQ-LC-017
def test_provided_timetable_converts_deterministically(cli, tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    r = cli("timetables", "--spec", REPO / "spec", "--out", a)
    assert r.rc == 0, r.err
    assert cli("timetables", "--spec", REPO / "spec", "--out", b).rc == 0
    assert (a / "d4_local_line.json").read_bytes() == (b / "d4_local_line.json").read_bytes()
    obj = json.loads((a / "d4_local_line.json").read_text(encoding="utf-8"))
    assert obj["schema"] == "railproof/timetable-json/1"
    assert (obj["name"], obj["line"]) == ("d4_local_line", "d4_local_line")
    assert obj["planned_time_step_ms"] == 15_000
    assert obj["driver"] == {"cruise_percent": [85, 100], "start_delay_ms": [0, 10_000],
                             "min_dwell_ms": 20_000}
    assert obj["communication"]["barrier_travel_ms"] == [4_000, 7_000]
    assert len(obj["services"]) == 40
    first = obj["services"][0]
    assert first["id"] == "101" and first["depart_ms"] == 6 * 3_600_000
    assert first["stops"] == [{"station": "S2", "dwell_ms": 30_000},
                              {"station": "S3", "dwell_ms": 75_000},
                              {"station": "S4", "dwell_ms": 30_000}]
    rapid = next(s for s in obj["services"] if s["id"] == "R105")
    assert rapid["stops"] == [{"station": "S3", "dwell_ms": 40_000}]
    assert not list(a.glob("*.tmp"))


_R105 = ('{id: "R105", train: dmu2_d4, running_line: up, depart: "07:31", stops: [S3], '
         'dwell_s: 40,')


@pytest.mark.parametrize("edit, entry, reason", [
    ((_R105, _R105.replace("[S3]", "[S7]")), "services[R105].stops[0]",
     "station 'S7' has no stop on running line up (stops: S1, S2, S3, S4, S5)"),
    ((_R105, _R105.replace("[S3]", "[S1]")), "services[R105].stops[0]",
     "stop at S1 is not between the origin S1 and the destination S5"),
    (('id: "101", train: dmu2_d4, running_line: up, depart: "06:00", stops: [S2, S3, S4]',
      'id: "101", train: dmu2_d4, running_line: up, depart: "06:00", stops: [S3, S2, S4]'),
     "services[101].stops[1]", "stop at S2 is not in running order (after S3)"),
    (('id: "101", train: dmu2_d4', 'id: "101", train: tram'), "services[101].train",
     "unknown train type 'tram' (no trains/tram.yaml)"),
    (('"101", train: dmu2_d4, running_line: up', '"101", train: dmu2_d4, running_line: left'),
     "services[101].running_line", "unknown running line 'left' of line d4_local_line"),
    (("line: d4_local_line", "line: d9_line"), "line", "unknown line 'd9_line'"),
    ((_R105, _R105.replace("dwell_s: 40", "dwell_s: 10")), "services[R105].stops[0]",
     "dwell 10 s at S3 is below the minimum dwell 20 s"),
    ((_R105, _R105.replace(" dwell_s: 40,", "")), "services[R105].stops[0]",
     "no dwell for the stop at 'S3'"),
    (('"101", train: dmu2_d4, running_line: up, depart: "06:00", stops: [S2, S3, S4], '
      'dwell_s: {default: 30, S3: 75}',
      '"101", train: dmu2_d4, running_line: up, depart: "06:00", stops: [S2, S3, S4], '
      'dwell_s: {default: 30, S9: 75}'), "services[101].dwell_s", "dwell for 'S9'"),
    (('{id: "102",', '{id: "101",'), "services[101]", "duplicate service id '101'"),
    ((_R105, _R105.replace("07:31", "06:59")), "services[R105].depart",
     "departure 06:59:00 is not after the departure 07:00:00 of services[103] from S1"),
    (('id: "101", train: dmu2_d4', 'id: "101", train: emu10_d2'), "services[101].from",
     "train emu10_d2 (200 m) does not fit platform S1"),
    (("cruise_percent: [85, 100]", "cruise_percent: [100, 85]"), "driver.cruise_percent",
     "min 100 % is greater than max 85 %"),
    (("min_dwell_s: 20 ", "min_dwell_s: 20.0005 "), "driver.min_dwell_s",
     "20.0005 s is not a whole number of milliseconds"),
    (("min_dwell_s: 20 ", "min_dwell_s: .nan "), "driver.min_dwell_s", "not a finite number"),
    (("min_dwell_s: 20 ", "min_dwell_s: 20\n  max_dwell_s: 90 "), "driver",
     "Additional properties are not allowed ('max_dwell_s'"),
    (('depart: "06:02"', 'depart: "6 am"'), "services[102]", "depart: '6 am' does not match"),
    (("name: d4_local_line", "name: d4_other"), "name", "must equal the file name"),
    (("source: [D5 §5.3, D4 §4.8.2, ASM-020, ASM-024]", "source: [hearsay, ASM-020, ASM-999]"),
     "d4_local_line", "source[0] 'hearsay' cites no D1-D5 section"),
    (("source: [D5 §5.3, D4 §4.8.2, ASM-020, ASM-024]", "source: [D5 §5.3, ASM-999]"),
     "d4_local_line", "source[1]: unknown assumption ASM-999"),
])
# @verifies REQ-LC-017
def test_rules_reject_with_file_entry_reason(tt_spec, cli, tmp_path, edit, entry, reason):
    spec = tt_spec(edit)
    out = tmp_path / "out"
    r = cli("timetables", "--spec", spec, "--out", out)
    assert r.rc == 1
    assert r.has(TT, entry, reason), r.err
    assert "nothing written" in r.err
    assert not out.exists()
    v = cli("validate", "--spec", spec)
    assert v.rc == 1
    assert v.has(TT, entry, reason), v.err


def test_every_finding_is_reported(tt_spec, cli, tmp_path):
    spec = tt_spec(("line: d4_local_line", "line: d9_line"),
                   (_R105, _R105.replace("dwell_s: 40", "dwell_s: 10")),
                   ("cruise_percent: [85, 100]", "cruise_percent: [100, 85]"))
    fails_with(cli("timetables", "--spec", spec, "--out", tmp_path / "out"),
               (TT, "line", "unknown line 'd9_line'"),
               (TT, "services[R105].stops[0]", "below the minimum dwell"),
               (TT, "driver.cruise_percent", "greater than max"))


def test_a_line_with_errors_is_named_as_such(tt_spec, cli, tmp_path):
    spec = tt_spec()
    line = spec / "lines/d4_local_line.yaml"
    line.write_text(line.read_text(encoding="utf-8").replace("length_m: 30500", "length_m: -1", 1),
                    encoding="utf-8")
    r = cli("timetables", "--spec", spec, "--out", tmp_path / "out")
    assert r.rc == 1
    assert r.has(TT, "line", "line 'd4_local_line' has errors (lines/d4_local_line.yaml")


def test_no_timetable_files_is_an_error(tmp_path, cli):
    (tmp_path / "spec/timetables").mkdir(parents=True)
    r = cli("timetables", "--spec", tmp_path / "spec", "--out", tmp_path / "out")
    assert r.rc == 1
    assert r.has("spec/timetables", "-", "no timetable files")
