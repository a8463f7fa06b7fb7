"""Property-based tests of the data converters (lines, trains, timetables), with Hypothesis
(settings and generators: strategies.py).

For each kind: every generated valid document validates and converts to the JSON the C++
reads; every single broken field is refused with a finding naming its entry and nothing is
written; and no document (any field replaced by any JSON value, or any bytes for the file)
makes a check raise anything but a finding."""
from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Callable, NamedTuple

import pytest
from hypothesis import given
from hypothesis import strategies as st

from conftest import FIXTURES, REPO
from railproof_testgen import checks, lines, timetables, trains
from railproof_testgen.__main__ import main
from strategies import (dump, json_values, line_breaks, paths, replaced, spec_tree,
                        timetable_breaks, train_breaks, valid_lines, valid_timetables,
                        valid_trains)
from test_lines import contract_problems

LINE_FILES = {"schemas/line.schema.json": REPO / "spec/schemas/line.schema.json",
              "assumptions/assumptions.yaml": FIXTURES / "lines/assumptions.yaml"}
TRAIN_FILES = {"schemas/train.schema.json": REPO / "spec/schemas/train.schema.json",
               "assumptions": REPO / "spec/assumptions"}
TIMETABLE_FILES = {"schemas/timetable.schema.json": REPO / "spec/schemas/timetable.schema.json"}

# The lines and train types the generated timetables run on: those of the real spec/.
_LINES, _ = lines.check_lines(REPO / "spec", checks.Report())
_TRAINS = {name: t for (mutant, name), t in
           trains.check_trains(REPO / "spec", checks.Report())[0].items() if not mutant}


def _convert(command, spec):
    """Run the converting command on spec into a fresh directory beside it: (exit status,
    output directory, stderr)."""
    out, err = spec.parent / "out", io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        rc = main([command, "--spec", str(spec), "--out", str(out)])
    return rc, out, err.getvalue()


def _converted(command, file, files, doc):
    """The JSON the converting command writes for doc (the file `file` of a tree holding
    `files`), which it must accept."""
    with spec_tree({file: dump(doc)}, files) as spec:
        rc, out, err = _convert(command, spec)
        assert rc == 0, err
        return json.loads((out / f"{Path(file).stem}.json").read_text(encoding="utf-8"))


def _check_line(text):
    with spec_tree({"lines/prop_line.yaml": text}, LINE_FILES) as spec:
        return lines.build(spec)


def _check_train(text):
    with spec_tree({"trains/prop_train.yaml": text}, TRAIN_FILES) as spec:
        return trains.build(spec)


def _check_timetable(text):
    with spec_tree({"timetables/d4_local_line.yaml": text}, TIMETABLE_FILES) as spec:
        report = checks.Report()
        outputs, _refs = timetables.check_timetables(spec, report, _LINES, _TRAINS)
        return outputs, report


def _names(report, entry):
    """True if a finding names the entry (the entry itself or a field or item inside it)."""
    return any(f.entry == entry or f.entry.startswith((entry + ".", entry + "["))
               for f in report.errors)


# --------------------------------------------------------------------------- lines

@given(doc=valid_lines())
def test_any_valid_line_converts(doc):
    obj = _converted("lines", "lines/prop_line.yaml", LINE_FILES, doc)
    assert contract_problems(obj) == []
    up, down = obj["running_lines"]
    assert up["length_mm"] == down["length_mm"] == doc["length_m"] * 1000
    assert len(up["balises"]) == len(doc["balises"])
    assert len(up["stations"]) == len(doc["stations"])
    assert [c["width_mm"] for c in up["level_crossings"]] == \
        [c["width_m"] * 1000 for c in doc["level_crossings"]]


# --------------------------------------------------------------------------- trains

@given(doc=valid_trains())
def test_any_valid_train_type_converts(doc):
    obj = _converted("trains", "trains/prop_train.yaml", TRAIN_FILES, doc)
    assert obj == dict(doc, schema=trains.JSON_SCHEMA)


# --------------------------------------------------------------------------- timetables

@given(doc=valid_timetables())
def test_any_valid_timetable_converts(doc):
    outputs, report = _check_timetable(dump(doc))
    assert report.errors == []
    obj = outputs["d4_local_line"]
    assert [s["id"] for s in obj["services"]] == [s["id"] for s in doc["services"]]
    for sv, out in zip(doc["services"], obj["services"]):
        dwell = sv.get("dwell_s")
        dwell = dwell["default"] if isinstance(dwell, dict) else dwell
        assert [s["dwell_ms"] for s in out["stops"]] == [dwell * 1000 for _ in sv["stops"]]
        assert out["depart_ms"] == timetables.clock_ms(sv["depart"])
    assert obj["planned_time_step_ms"] == doc["planned_time_step_s"] * 1000


# --------------------------------------------------------------------------- every kind

class Kind(NamedTuple):
    valid: st.SearchStrategy  # valid documents
    breaks: Callable  # doc -> [(entry, path, refused values)]
    check: Callable  # file text -> (outputs, report)
    command: str | None  # the converting command, run on a broken file (None: not run here)
    file: str  # the file's path in the spec tree
    files: dict  # what the tree holds besides


KINDS = {
    "line": Kind(valid_lines(), line_breaks, _check_line, "lines", "lines/prop_line.yaml",
                 LINE_FILES),
    "train": Kind(valid_trains(), train_breaks, _check_train, "trains",
                  "trains/prop_train.yaml", TRAIN_FILES),
    # the timetable command checks every line and train type of its tree first: the
    # timetables are checked against the real ones, loaded once (nothing written is
    # shown for the shared converter by the lines and trains)
    "timetable": Kind(valid_timetables(), timetable_breaks, _check_timetable, None,
                      "timetables/d4_local_line.yaml", TIMETABLE_FILES),
}


@pytest.mark.parametrize("kind", sorted(KINDS))
@given(data=st.data())
def test_any_broken_field_is_refused_naming_its_entry(kind, data):
    k = KINDS[kind]
    doc = data.draw(k.valid)
    entry, path, values = data.draw(st.sampled_from(k.breaks(doc)))
    bad = dump(replaced(doc, path, data.draw(st.sampled_from(values))))
    outputs, report = k.check(bad)
    assert report.errors and not outputs
    assert _names(report, entry), (entry, report.errors)
    if k.command:
        with spec_tree({k.file: bad}, k.files) as spec:
            rc, out, _err = _convert(k.command, spec)
            assert rc == 1 and not out.exists()


@pytest.mark.parametrize("kind", sorted(KINDS))
@given(data=st.data())
def test_no_field_of_any_value_makes_a_check_raise(kind, data):
    k = KINDS[kind]
    doc = data.draw(k.valid)
    path = data.draw(st.sampled_from(paths(doc)))
    k.check(dump(replaced(doc, path, data.draw(json_values))))


@pytest.mark.parametrize("kind", sorted(KINDS))
@given(text=st.one_of(st.binary(max_size=400).map(lambda b: b.decode("latin-1")),
                      st.text(alphabet="{}[]:,-&*!|>'\"#%@`?\n\t .0123456789abcxyz",
                              max_size=400)))
def test_no_file_content_makes_a_check_raise(kind, text):
    _outputs, report = KINDS[kind].check(text)
    assert report.errors
