"""Train types (spec/trains, REQ-BR-010): the provided types validate and convert; each rule
rejects a broken entry with 'file: entry: reason'; nothing is written on error; the
negative-test type is converted with its broken design rule listed; output deterministic."""
from __future__ import annotations

import json
import shutil
from argparse import Namespace

import pytest

from conftest import REPO
from railproof_testgen import trains

PROVIDED = ["dmu2_d4", "emu10_d2", "emu3_d1"]


@pytest.fixture
def train_spec(tmp_path):
    """train_spec(*edits) -> spec dir with emu3_d1.yaml (text edits applied), the mutant,
    the real schema and the real assumptions."""

    def make(*edits):
        spec = tmp_path / "spec"
        if spec.exists():
            shutil.rmtree(spec)
        (spec / "trains" / "mutants").mkdir(parents=True)
        (spec / "schemas").mkdir()
        shutil.copytree(REPO / "spec/assumptions", spec / "assumptions")
        shutil.copy(REPO / "spec/schemas/train.schema.json", spec / "schemas")
        shutil.copy(REPO / "spec/trains/mutants/emu3_d1_weak.yaml", spec / "trains/mutants")
        text = (REPO / "spec/trains/emu3_d1.yaml").read_text(encoding="utf-8")
        for old, new in edits:
            assert text.count(old) == 1, old
            text = text.replace(old, new)
        (spec / "trains" / "emu3_d1.yaml").write_text(text, encoding="utf-8")
        return spec

    return make


def _run(spec, out, capsys):
    rc = trains.run(Namespace(spec=str(spec), out=str(out)))
    return rc, capsys.readouterr()


# @verifies REQ-BR-010
def test_provided_types_convert_deterministically(tmp_path, capsys):
    rc, _ = _run(REPO / "spec", tmp_path / "a", capsys)
    assert rc == 0
    rc, _ = _run(REPO / "spec", tmp_path / "b", capsys)
    assert rc == 0
    for name in PROVIDED:
        a = (tmp_path / "a" / f"{name}.json").read_bytes()
        assert a == (tmp_path / "b" / f"{name}.json").read_bytes()
        obj = json.loads(a)
        assert obj["schema"] == "railproof/train-json/1" and obj["name"] == name
        assert "design_rule_violations" not in obj
        assert obj["braking"]["emergency_pattern_mm_s2"] <= \
            obj["uncertainty"]["emergency_deceleration_mm_s2"][0]
    weak = json.loads((tmp_path / "a/mutants/emu3_d1_weak.json").read_text())
    assert any("REQ-BR-010" in r for r in weak["design_rule_violations"])


@pytest.mark.parametrize("edit, entry, reason", [
    (("emergency_pattern_mm_s2: 1000", "emergency_pattern_mm_s2: 1200"), "emu3_d1.braking",
     "exceeds the lowest real emergency deceleration 1100"),
    (("service_pattern_mm_s2: 900", "service_pattern_mm_s2: 1050"), "emu3_d1.braking",
     "exceeds the emergency pattern deceleration"),
    (("emergency_free_running_ms: [500, 1500]", "emergency_free_running_ms: [1500, 500]"),
     "braking.emergency_free_running_ms", "min > max"),
    (("name: emu3_d1", "name: emu3_x"), "emu3_x", "must equal the file name"),
    (("source: [\"D1 §3 item 9\", \"D5 §5.5\", ASM-024]", "source: [hearsay]"), "emu3_d1",
     "cites no D1-D5 section"),
    (("assumption: ASM-024", "assumption: ASM-999"), "emu3_d1", "unknown assumption ASM-999"),
    (("accel_max_mm_s2: 920", "accel_max_mm_s2: -1"), "accel_max_mm_s2", "minimum"),
    (("length_mm: 60000", "length_mm: 60000\ncolour: red"), "-", "Additional properties"),
])
# @verifies REQ-BR-010
def test_rules_reject_with_file_entry_reason(train_spec, tmp_path, capsys, edit, entry, reason):
    spec = train_spec(edit)
    rc, io = _run(spec, tmp_path / "out", capsys)
    assert rc == 1
    assert "nothing written" in io.err
    lines = [ln for ln in io.out.splitlines() + io.err.splitlines() if "emu3_d1.yaml" in ln]
    assert any(f": {entry}: " in ln and reason in ln for ln in lines), lines
    assert not (tmp_path / "out").exists()
