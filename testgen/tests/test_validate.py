"""Specification checker: every class of spec error is reported as
'file: entry: reason' with exit code 1, and all of them are collected."""
from __future__ import annotations

import json

import jsonschema
import pytest

from conftest import REPO, fails_with
from railproof_testgen import params, validate
from railproof_testgen.errors import SpecError


@pytest.fixture
def validate_cmd(cli):
    """validate_cmd(root) runs the validate command on the spec/ of a fixture repository."""
    return lambda root: cli("validate", "--spec", root / "spec")


def test_schemas_are_valid_draft_2020_12():
    for f in sorted((REPO / "spec" / "schemas").glob("*.schema.json")):
        schema = json.loads(f.read_text(encoding="utf-8"))
        if f.name.split(".")[0] in validate.KINDS:
            assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
        jsonschema.Draft202012Validator.check_schema(schema)


def test_real_spec_passes(cli):
    r = cli("validate", "--spec", REPO / "spec")
    assert r.rc == 0, r.err
    assert r.lines == []
    assert "ok" in r.out


def test_valid_fixture_passes_and_returns_model(tree, validate_cmd):
    root = tree()
    r = validate_cmd(root)
    assert r.rc == 0, r.err
    model = validate.validate_spec(root / "spec")
    assert sorted(model["requirements"]) == ["REQ-MB-001", "REQ-TG-001", "REQ-TG-002",
                                             "REQ-TG-003", "REQ-TG-004"]
    assert model["requirements"]["REQ-MB-001"]["area"] == "MB"
    assert model["requirements"]["REQ-TG-001"]["file"].endswith("requirements/tg.yaml")
    assert sorted(model["hazards"]) == ["HAZ-001", "HAZ-002", "HAZ-003"]
    assert sorted(model["assumptions"]) == ["ASM-001", "ASM-002"]
    assert sorted(model["justifications"]) == ["UR-TG-001"]
    tg = model["parameters"]["TG"]
    assert tg["parameters"]["crc16_poly"]["value"] == 0x1021
    assert list(tg["model_bounds"]) == ["model_seq_modulus"]


@pytest.mark.parametrize("case, file, entry, fragment", [
    ("malformed_yaml", "hazards/hazards.yaml", "line 5", "malformed YAML"),
    ("duplicate_key", "assumptions/assumptions.yaml", "line 9", "duplicate key 'title'"),
    ("duplicate_id", "requirements/tg_extra.yaml", "REQ-TG-001",
     "duplicate id (first defined in"),
    ("bad_id", "requirements/tg.yaml", "REQ-TG-03", "does not match"),
    ("unknown_hazard", "requirements/mb.yaml", "REQ-MB-001",
     "hazards[1]: unknown hazard HAZ-009"),
    ("unknown_asm", "requirements/mb.yaml", "REQ-MB-001",
     "source[1]: unknown assumption ASM-042"),
    ("bad_sil", "requirements/mb.yaml", "REQ-MB-001",
     "sil: 5 is greater than the maximum of 4"),
    ("review_only_sil4", "requirements/tg.yaml", "REQ-TG-003",
     "verified by review alone"),
])
def test_spec_error_classes(tree, validate_cmd, case, file, entry, fragment):
    fails_with(validate_cmd(tree(case)), (file, entry, fragment))


def test_duplicate_id_names_both_files(tree, validate_cmd):
    r = validate_cmd(tree("duplicate_id"))
    line = next(ln for ln in r.lines if "duplicate id" in ln)
    assert "tg_extra.yaml: REQ-TG-001:" in line
    assert "requirements/tg.yaml)" in line


def test_duplicate_id_within_one_file(tree, validate_cmd):
    root = tree(edits=[("spec/hazards/hazards.yaml", "id: HAZ-002", "id: HAZ-001")])
    fails_with(validate_cmd(root), ("hazards/hazards.yaml", "HAZ-001", "duplicate id"))


@pytest.mark.parametrize("old, new, file, entry, fragment", [
    # id area must match the file's area
    ("id: REQ-TG-004", "id: REQ-MB-004", "requirements/tg.yaml", "REQ-MB-004",
     "does not match the file's area TG"),
    # unknown verification method (schema enum)
    ("verification: [analysis]", "verification: [simulation]", "requirements/tg.yaml",
     "REQ-TG-004", "verification[0]: 'simulation' is not one of"),
    # source must cite D1-D5 §, an ASM or a named standard
    ("source: [D5 §6]", "source: [the prototype report]", "requirements/tg.yaml",
     "REQ-TG-004", "source[0] 'the prototype report' cites no D1-D5 section"),
    # a D-citation needs a section
    ("source: [D5 §6]", "source: [D5]", "requirements/tg.yaml", "REQ-TG-004",
     "cites no D1-D5 section"),
    # malformed reference inside free text
    ("text: The residual error rate is below the target.",
     "text: The residual error rate is below the target (ASM-TG-003).",
     "requirements/tg.yaml", "REQ-TG-004", "text: malformed reference 'ASM-TG-003'"),
    # dangling requirement reference inside free text
    ("(see REQ-TG-002)", "(see REQ-TG-042)", "requirements/tg.yaml", "REQ-TG-001",
     "text: unknown requirement REQ-TG-042"),
    # missing required field
    ("    sil: 2\n", "", "requirements/tg.yaml", "REQ-TG-003",
     "'sil' is a required property"),
    # misspelt field
    ("    hazards: []\n", "    hazard: []\n", "requirements/tg.yaml", "REQ-TG-003",
     "'hazard' was unexpected"),
])
def test_requirement_rules(tree, validate_cmd, old, new, file, entry, fragment):
    fails_with(validate_cmd(tree(edits=[(f"spec/{file}", old, new)])), (file, entry, fragment))


def test_unaddressed_hazard_is_an_error(tree, validate_cmd):
    root = tree(edits=[("spec/requirements/mb.yaml", "hazards: [HAZ-003]", "hazards: [HAZ-001]")])
    fails_with(validate_cmd(root),
               ("hazards/hazards.yaml", "HAZ-003", "not addressed by any requirement"))


@pytest.mark.parametrize("old, new, entry, fragment", [
    ("requirements: [REQ-TG-001]", "requirements: [REQ-TG-077]", "seq_bits",
     "requirements[0]: unknown requirement REQ-TG-077"),
    ("source: ASM-002", "source: ASM-009", "seq_bits", "source: unknown assumption ASM-009"),
    ("source: ASM-002", "source: chosen by us", "seq_bits", "cites no D1-D5 section"),
    ("value: 32", "value: thirty-two", "seq_bits", "'thirty-two' is not of type 'number'"),
    ("value: 32", "value: true", "seq_bits", "True is not of type 'number'"),
    ("id: crc16_poly", "id: seq_bits", "seq_bits", "duplicate parameter id"),
    ("id: model_seq_modulus", "id: seq_bits", "seq_bits", "duplicate parameter id"),
    ("id: crc16_poly", "id: Crc16Poly", "Crc16Poly", "does not match"),
    ("rationale: reduced width for the model (ASM-002)",
     "rationale: reduced width for the model (ASM-003)", "model_seq_modulus",
     "rationale: unknown assumption ASM-003"),
])
def test_parameter_rules(tree, validate_cmd, old, new, entry, fragment):
    fails_with(validate_cmd(tree(edits=[("spec/parameters/tg.yaml", old, new)])),
               ("parameters/tg.yaml", entry, fragment))


def test_two_parameter_files_for_one_area(tree, validate_cmd):
    root = tree()
    src = root / "spec/parameters/tg.yaml"
    (root / "spec/parameters/tg2.yaml").write_text(src.read_text(encoding="utf-8"),
                                                         encoding="utf-8")
    fails_with(validate_cmd(root), ("parameters/tg2.yaml", "area", "also declared by"))


def test_justification_rules(tree, validate_cmd):
    root = tree(edits=[("spec/justifications/tg.yaml", "id: UR-TG-001", "id: UR-XX-001")])
    fails_with(validate_cmd(root), ("justifications/tg.yaml", "UR-XX-001", "does not match"))


def test_yml_extension_is_not_silently_ignored(tree, validate_cmd):
    root = tree()
    (root / "spec/hazards/more.yml").write_text("schema: railproof/hazards/1\n",
                                                encoding="utf-8")
    fails_with(validate_cmd(root), ("hazards/more.yml", "-", "use the .yaml extension"))


def test_unreferenced_assumption_is_a_warning(tree, validate_cmd):
    root = tree(edits=[("spec/parameters/tg.yaml", "source: ASM-001", "source: D5 §6.3"),
                       ("spec/requirements/tg.yaml", "[EN 50159 §7.3, ASM-001]",
                        "[EN 50159 §7.3]")])
    r = validate_cmd(root)
    assert r.rc == 0, r.err
    assert r.warned("assumptions/assumptions.yaml", "ASM-001", "not referenced")


def test_all_errors_are_collected_across_files(tree, validate_cmd):
    r = validate_cmd(tree("malformed_yaml", "unknown_asm", "bad_id", "duplicate_key"))
    fails_with(r, ("hazards/hazards.yaml", "line 5", "malformed YAML"),
               ("assumptions/assumptions.yaml", "line 9", "duplicate key"),
               ("requirements/mb.yaml", "REQ-MB-001", "unknown assumption ASM-042"),
               ("requirements/tg.yaml", "REQ-TG-03", "does not match"),
               # the unreadable hazards file leaves every hazard reference dangling: reported too
               ("requirements/tg.yaml", "REQ-TG-001", "unknown hazard HAZ-001"))
    assert len(r.lines) >= 6
    assert r.lines[-1].startswith("validate: ")


def test_validate_spec_raises_first_error_with_count(tree):
    root = tree("unknown_hazard", "review_only_sil4")
    with pytest.raises(SpecError) as exc:
        validate.validate_spec(root / "spec")
    assert exc.value.file.endswith("mb.yaml")
    assert exc.value.entry == "REQ-MB-001"
    assert exc.value.reason.endswith("unknown hazard HAZ-009 (and 1 more)")


def test_gen_params_refuses_an_invalid_spec(tree, tmp_path, cli):
    root = tree("unknown_hazard")
    out = tmp_path / "gen"
    with pytest.raises(SpecError):
        params.generate(root / "spec", out)
    assert not out.exists()
    r = cli("gen-params", "--spec", root / "spec", "--out", out)
    assert r.rc == 1
    assert len(r.lines) == 1
    assert r.lines[0].startswith("railproof_testgen: error: ")
    assert "mb.yaml: REQ-MB-001: hazards[1]: unknown hazard HAZ-009" in r.lines[0]


def test_gen_params_on_valid_spec(tree, tmp_path, cli):
    root = tree()
    r = cli("gen-params", "--spec", root / "spec", "--out", tmp_path / "gen")
    assert r.rc == 0, r.err
    hdr = (tmp_path / "gen/include/railproof/generated/tg_params.hpp").read_text()
    assert "inline constexpr auto crc16_poly = std::int64_t{4129};" in hdr


def test_missing_schema_is_reported(tree, validate_cmd):
    root = tree()
    (root / "spec/schemas/hazards.schema.json").unlink()
    fails_with(validate_cmd(root), ("schemas/hazards.schema.json", "-", "schema file not found"))
