"""Bad input, class by class (issue 14): each case runs a command of railproof_testgen on
one hostile input and asserts the exact ``file: entry: reason`` line, exit status 1, that
nothing was written (no output, no temporary file), and, where the input is built to
exhaust time or memory, that the limit bounding the work is the one that fired (its own
message: the limit is checked before the expansion it bounds; no case measures time).

Classes: parameter values (NaN, infinite, negative, fractional where an integer is meant,
beyond 64 bits, beyond their unit's range); files that are not data (a directory, a
device, a pipe, too large, not UTF-8); YAML and JSON that would expand (alias bomb, a
cyclic alias, deep nesting, long strings, too many values, huge integers) or that are not
JSON's values (dates, sets, keys that are not strings); data whose size would be expanded
(a line of extreme length or block size); a timetable whose check grew with the square of
its length; values beyond their schema's range in scenarios; output paths that cannot be
written."""
from __future__ import annotations

import json
import os
import shutil

import pytest

from conftest import FIXTURES, REPO
from railproof_testgen import spec as spec_mod

MINI = FIXTURES / "lines" / "mini_line.yaml"


def _files(root):
    """Every file and directory under root (relative), for 'nothing was written'."""
    return sorted(str(p.relative_to(root)) for p in root.rglob("*")) if root.exists() else []


def _line_spec(tmp_path, text=None, params=False):
    """A spec tree holding the miniature line (or `text` as its file), the real line schema,
    its assumption and, with params, the real spec/parameters and their schema."""
    spec = tmp_path / "spec"
    (spec / "lines").mkdir(parents=True)
    (spec / "schemas").mkdir()
    (spec / "assumptions").mkdir()
    shutil.copy(REPO / "spec/schemas/line.schema.json", spec / "schemas")
    shutil.copy(FIXTURES / "lines/assumptions.yaml", spec / "assumptions")
    if params:
        shutil.copytree(REPO / "spec/parameters", spec / "parameters")
    path = spec / "lines" / "mini_line.yaml"
    path.write_text(MINI.read_text(encoding="utf-8") if text is None else text, encoding="utf-8")
    return spec, path


def _mini(old, new):
    text = MINI.read_text(encoding="utf-8")
    assert text.count(old) == 1, old
    return text.replace(old, new)


def _refused(r, line, out=None):
    """The run failed with exit status 1, printed `line` exactly, and wrote nothing."""
    assert r.rc == 1, r.err
    assert line in r.err.splitlines(), (line, r.err)
    assert "Traceback" not in r.err
    if out is not None:
        assert _files(out) == [], _files(out)


# --------------------------------------------------------------------------- parameters

@pytest.mark.parametrize("old, new, entry, reason", [
    ("value: 32", "value: .nan", "parameters[seq_bits].value", "not a finite number"),
    ("value: 32", "value: .inf", "parameters[seq_bits].value", "not a finite number"),
    ("value: 32", "value: -32", "seq_bits",
     "value: -32 is less than the minimum of 1 (a width in bits, from 1 to 64)"),
    ("value: 32", "value: 32.5", "seq_bits",
     "value: 32.5 is not of type 'integer' (a width in bits, from 1 to 64)"),
    ("value: 32", "value: 32.0", "seq_bits",
     "value: 32.0 is not of type 'integer' (a width in bits, from 1 to 64)"),
    ("value: 0x1021", "value: 99999999999999999999", "crc16_poly",
     "value: 99999999999999999999 is greater than the maximum of 4294967295 "
     "(a bit pattern of at most 32 bits)"),
    ("value: 0x1021", "value: " + "9" * 41, "line 10",
     "YAML beyond the loader's limits: an integer of 41 digits is beyond 64 bits"),
    ("value: 16", "value: 2147483648", "model_seq_modulus",
     "value: 2147483648 is greater than the maximum of 2147483647 (a model bound, whole, "
     "from 0 to 2^31 - 1)"),
    ("unit: bit", "unit: furlong", "seq_bits", "unit: 'furlong' is not one of"),
])
def test_a_bad_parameter_value_is_refused_before_any_header_is_written(tree, cli, tmp_path,
                                                                         old, new, entry, reason):
    root = tree(edits=[("spec/parameters/tg.yaml", old, new)])
    out = tmp_path / "gen"
    r = cli("gen-params", "--spec", root / "spec", "--out", out)
    assert r.rc == 1 and not out.exists()
    first = r.err.splitlines()[0]
    prefix = f"railproof_testgen: error: {root}/spec/parameters/tg.yaml: {entry}: {reason}"
    assert first.startswith(prefix), (prefix, r.err)
    v = cli("validate", "--spec", root / "spec")
    assert v.rc == 1 and any(ln.startswith(prefix.split("error: ", 1)[1]) for ln in v.lines)


# --------------------------------------------------------------------------- files

def test_a_directory_where_a_file_is_expected(tmp_path, cli):
    spec, path = _line_spec(tmp_path)
    path.unlink()
    path.mkdir()
    _refused(cli("lines", "--spec", spec, "--out", tmp_path / "out"),
             f"{path}: -: is a directory, not a file", tmp_path / "out")
    _refused(cli("validate", "--spec", REPO / "spec", "--data", path),
             f"{path}: -: is a directory, not a file")


@pytest.mark.parametrize("special", ["device", "pipe"])
def test_a_device_or_pipe_is_not_read(tmp_path, cli, special):
    """/dev/zero would never end and a pipe would block the read: neither is opened."""
    spec, path = _line_spec(tmp_path)
    path.unlink()
    if special == "device":
        path.symlink_to("/dev/zero")
    else:
        os.mkfifo(path)
    _refused(cli("lines", "--spec", spec, "--out", tmp_path / "out"),
             f"{path}: -: not a regular file", tmp_path / "out")


def test_a_file_beyond_the_size_limit_is_not_read(tmp_path, cli):
    text = MINI.read_text(encoding="utf-8")
    text += "#" * (spec_mod.MAX_FILE_BYTES + 1 - len(text.encode("utf-8"))) + "\n"
    spec, path = _line_spec(tmp_path, text)
    _refused(cli("lines", "--spec", spec, "--out", tmp_path / "out"),
             f"{path}: -: file larger than the limit of {spec_mod.MAX_FILE_BYTES} bytes "
             f"({spec_mod.MAX_FILE_BYTES + 2} bytes)", tmp_path / "out")


def test_a_file_that_is_not_utf8(tmp_path, cli):
    spec, path = _line_spec(tmp_path)
    data = MINI.read_bytes().replace(b"Miniature test line", b"Miniature test l\xefne", 1)
    path.write_bytes(data)
    offset = data.index(b"\xef")
    line = data[:offset].count(b"\n") + 1
    _refused(cli("lines", "--spec", spec, "--out", tmp_path / "out"),
             f"{path}: line {line}: not UTF-8 text (byte 0xef at offset {offset})",
             tmp_path / "out")


# --------------------------------------------------------------------------- YAML and JSON

BOMB = ("".join(f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}" if i else '"lol"'] * 10) + "]\n"
                for i in range(9)))


@pytest.mark.parametrize("text, line, reason", [
    # nine levels of ten aliases stand for 10^9 strings: refused by the expanded size, which
    # is measured on the composed nodes without expanding them
    (BOMB, 6, f"YAML beyond the loader's limits: more than {spec_mod.MAX_NODES} values "
              "(aliases expanded)"),
    ("a: &a [1, *a]\n", 1, "YAML beyond the loader's limits: an alias refers to a value "
                           "that contains it"),
    ("a: &a [1]\nb: [" + ", ".join(["*a"] * (spec_mod.MAX_ALIASES + 1)) + "]\n", 2,
     f"YAML beyond the loader's limits: more than {spec_mod.MAX_ALIASES} aliases"),
    ("a: " + "[" * 40 + "]" * 40 + "\n", 1,
     f"YAML beyond the loader's limits: nested deeper than {spec_mod.MAX_DEPTH} levels"),
    ("a: " + "x" * (spec_mod.MAX_STRING + 1) + "\n", 1,
     f"YAML beyond the loader's limits: a value of {spec_mod.MAX_STRING + 1} characters "
     f"exceeds the limit of {spec_mod.MAX_STRING}"),
    ("a: [" + "0," * spec_mod.MAX_NODES + "0]\n", 1,
     f"YAML beyond the loader's limits: more than {spec_mod.MAX_NODES} values"),
    ("a: 2024-05-17\n", 1, "malformed YAML: a timestamp is not a value of JSON (write it in "
                           "quotes if it is text)"),
    ("a: !!set {x, y}\n", 1, "malformed YAML: a set is not a value of JSON (write it in "
                             "quotes if it is text)"),
    ("1: one\n", 1, "malformed YAML: key '1' is not a string (write it in quotes)"),
    ("a: !!int twelve\n", 1, "malformed YAML: 'twelve' cannot be read as int"),
    ("a: 1\na: 2\n", 2, "malformed YAML: duplicate key 'a'"),
], ids=["alias bomb", "cyclic alias", "aliases", "depth", "string", "values", "date", "set",
        "integer key", "bad tag", "duplicate key"])
def test_yaml_beyond_the_limits_or_outside_json(tmp_path, cli, text, line, reason):
    spec, path = _line_spec(tmp_path, text)
    _refused(cli("lines", "--spec", spec, "--out", tmp_path / "out"),
             f"{path}: line {line}: {reason}", tmp_path / "out")


@pytest.mark.parametrize("text, entry, reason", [
    ('{"a": ' + "[" * 40 + "]" * 40 + "}", "line 1",
     f"JSON beyond the loader's limits: nested deeper than {spec_mod.MAX_DEPTH} levels"),
    ('{"a": ' + "1" * 41 + "}", "-", "malformed JSON: an integer of 41 digits is beyond 64 bits"),
    ('{"a": 1e400}', "-", "malformed JSON: number 1e400 is out of range"),
    ('{"a": "' + "x" * (spec_mod.MAX_STRING + 1) + '"}', "a",
     f"a value of {spec_mod.MAX_STRING + 1} characters exceeds the limit of {spec_mod.MAX_STRING}"),
], ids=["depth", "integer", "number", "string"])
def test_json_beyond_the_limits(tmp_path, cli, text, entry, reason):
    path = tmp_path / "run.json"
    path.write_text(text, encoding="utf-8")
    _refused(cli("validate", "--spec", REPO / "spec", "--data", path),
             f"{path}: {entry}: {reason}")


def test_a_non_finite_number_in_line_data_names_its_entry(tmp_path, cli):
    spec, path = _line_spec(tmp_path, _mini("{id: B2, track: main, at_m: 950}",
                                            "{id: B2, track: main, at_m: .nan}"))
    _refused(cli("lines", "--spec", spec, "--out", tmp_path / "out"),
             f"{path}: balises[B2].at_m: not a finite number", tmp_path / "out")


# --------------------------------------------------------------------------- expansion

@pytest.mark.parametrize("params, limit", [(True, 16384), (False, 1 << 20)])
def test_a_line_of_extreme_length_and_tiny_blocks_is_refused_by_its_block_count(
        tmp_path, cli, params, limit):
    """10^12 blocks of 1 mm over 1000 km: counted from the entry's range and block length,
    refused by max_blocks; the blocks are never listed (that took minutes and gigabytes)."""
    text = _mini("length_m: 2000", "length_m: 1000000")
    for old, new in (("{from_m: 1000, to_m: 2000, permille: -3}",
                      "{from_m: 1000, to_m: 1000000, permille: -3}"),
                     ("{from_m: 1000, to_m: 2000, kmh: 60}", "{from_m: 1000, to_m: 1000000, kmh: 60}"),
                     ("{id: C2, from_m: 1000, to_m: 2000}", "{id: C2, from_m: 1000, to_m: 1000000}"),
                     ("{km: 12.0, at_m: 2000}", "{km: 1010.0, at_m: 1000000}"),
                     ("{track: main, from_m: 0, to_m: 2000, length_m: 100}",
                      "{track: main, from_m: 0, to_m: 1000000, length_m: 0.001}")):
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    spec, path = _line_spec(tmp_path, text, params=params)
    where = "(spec/parameters)" if params else ("(without spec/parameters: the largest count "
                                                "spec/schemas/parameters.schema.json admits)")
    _refused(cli("lines", "--spec", spec, "--out", tmp_path / "out"),
             f"{path}: tracks[main]: 1000000000 virtual blocks exceed max_blocks {limit} {where}",
             tmp_path / "out")


def test_a_timetable_of_mixed_stops_is_checked_in_linear_time(tmp_path, cli):
    """Stops mixing numbers and names cannot be sorted, and jsonschema compared every pair
    of them for uniqueItems (minutes for a long list); the check hashes them instead and
    names the first repeated stop."""
    spec = tmp_path / "spec"
    shutil.copytree(REPO / "spec", spec)
    path = spec / "timetables/d4_local_line.yaml"
    text = path.read_text(encoding="utf-8")
    old = 'stops: [S3], dwell_s: 40, note: "rapid: calls at S3 only"'
    assert text.count(old) == 1
    stops = ", ".join(["S3", "1"] * 5_000)
    path.write_text(text.replace(old, f"stops: [{stops}], dwell_s: 40"), encoding="utf-8")
    r = cli("timetables", "--spec", spec, "--out", tmp_path / "out")
    _refused(r, f"{path}: services[R105]: stops: 'S3' occurs more than once", tmp_path / "out")


# --------------------------------------------------------------------------- ranges

@pytest.mark.parametrize("file, edit, entry, reason", [
    ("scenarios/d1_faults.json", lambda o: o["trains"][0].__setitem__(
        "resistance", {"a0": 1e300, "a1": 0.02, "a2": 0.0003}),
     "trains[2]", "resistance.a0: 1e+300 is greater than the maximum of 100 (N/kN, at most 100 (a "
                  "deceleration of 0.1 g from resistance alone))"),
    # the former supervision stand-in is no key of a scenario any more: refused, not ignored
    ("scenarios/d1_faults.json", lambda o: o.__setitem__("supervision", {"margin_m": 10}),
     "-", "Additional properties are not allowed ('supervision' was unexpected)"),
    ("scenarios/d1_faults.json", lambda o: o["trains"][0].__setitem__("initial_front_m", 1e12),
     "trains[2]", "initial_front_m: 1000000000000.0 is greater than the maximum of 1000000 "
                  "(metres on the running line, 0 to 1000 km (the longest line of the line "
                  "format, line.schema.json))"),
    ("wheelrail/micro_slips.json", lambda o: o.setdefault("curves", []).append(
        {"begin_m": 200, "end_m": 300, "radius_m": 50}),
     "curves[0]", "radius_m: 50 should not be valid under {'exclusiveMinimum': -100, "
                  "'exclusiveMaximum': 100}"),
])
def test_values_beyond_their_range_in_scenarios(tmp_path, cli, file, edit, entry, reason):
    obj = json.loads((REPO / "spec" / file).read_text(encoding="utf-8"))
    edit(obj)
    path = tmp_path / file.split("/")[1]
    path.write_text(json.dumps(obj), encoding="utf-8")
    _refused(cli("validate", "--spec", REPO / "spec", "--data", path), f"{path}: {entry}: {reason}")


# --------------------------------------------------------------------------- outputs

def test_an_output_path_under_a_file(tmp_path, cli):
    blocker = tmp_path / "file"
    blocker.write_text("", encoding="utf-8")
    r = cli("trains", "--spec", REPO / "spec", "--out", blocker / "trains")
    _refused(r, f"railproof_testgen: error: {blocker}/trains/dmu2_d4.json: -: cannot write: "
                f"{blocker} is not a directory")
    assert _files(tmp_path) == ["file"]


def test_an_output_that_is_a_directory_leaves_the_other_outputs_untouched(tmp_path, cli):
    """The outputs are one set: the train types before the failing one in the set are not
    written either, and no temporary file stays behind."""
    out = tmp_path / "trains"
    (out / "mutants" / "emu3_d1_weak.json").mkdir(parents=True)
    r = cli("trains", "--spec", REPO / "spec", "--out", out)
    _refused(r, f"railproof_testgen: error: {out}/mutants/emu3_d1_weak.json: -: cannot write: "
                "is a directory, not a file")
    assert _files(out) == ["mutants", "mutants/emu3_d1_weak.json"]


def test_gen_params_into_a_path_under_a_file(tmp_path, cli):
    blocker = tmp_path / "gen"
    blocker.write_text("", encoding="utf-8")
    r = cli("gen-params", "--spec", REPO / "spec", "--out", blocker)
    _refused(r, f"railproof_testgen: error: {blocker}/include/railproof/generated/br_params.hpp: "
                f"-: cannot write: {blocker} is not a directory")
    assert _files(tmp_path) == ["gen"]
