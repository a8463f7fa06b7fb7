"""The capability registry (spec/capabilities.yaml) and its check against the tree: the real
tree agrees with it, and every kind of disagreement is found, named by file, entry and
reason. Each case works on a copy of the parts of the repository the check reads."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from conftest import REPO, edit

from railproof_testgen import registry

PARTS = ("spec", "models", "proofs", "evidence/templates", "testgen/railproof_testgen/capabilities",
         "cpp/runtime", "cpp/offline")


@pytest.fixture
def repo(tmp_path):
    for part in PARTS:
        skip = shutil.ignore_patterns("corpus", "data", "bench") if part.startswith("cpp/") else None
        shutil.copytree(REPO / part, tmp_path / part, ignore=skip)
    return tmp_path


def _check(cli, root):
    return cli("registry", "--spec", root / "spec", "--repo", root, "--check")


def test_the_tree_agrees_with_the_registry(cli, repo):
    r = _check(cli, repo)
    assert r.rc == 0, r.err
    reg = registry.load(repo / "spec")
    assert [c.name for c in reg.capabilities] == ["tg", "mb", "br", "ra", "lc", "fc"]
    assert [f.id for f in reg.units.faults][:2] == ["FAULT_UNIT_REAR_FOR_FRONT", "FAULT_UNIT_RESTRICTION_DROPPED"]
    assert reg.of_area("SC").name == "br"
    assert reg.of_model("models/lc.pml").name == "lc"


def test_cmake_variables_and_fault_identifiers_come_from_the_registry(cli, tmp_path):
    r = cli("registry", "--spec", REPO / "spec", "--repo", REPO, "--cmake", tmp_path / "c.cmake",
            "--faults-header", tmp_path / "f.hpp")
    assert r.rc == 0, r.err
    cmake = (tmp_path / "c.cmake").read_text(encoding="utf-8")
    assert "set(RAILPROOF_CAPABILITIES tg mb br ra lc fc)" in cmake
    assert "set(RAILPROOF_CAP_units_FAULTS_UNIT FAULT_UNIT_REAR_FOR_FRONT" in cmake
    assert "set(RAILPROOF_CAP_br_AREAS BR SC)" in cmake
    assert "FAULT_LC_CLEAR_ON_ANY_CLOSED" in cmake
    header = (tmp_path / "f.hpp").read_text(encoding="utf-8")
    assert "enum class SeededFault" in header and '"FAULT_TG_NO_REPEAT_CHECK",' in header


@pytest.mark.parametrize("change, file, entry, fragment", [
    # a model configuration the registry does not list
    (("spec/capabilities.yaml", "configurations: [default, ONE_START, UNIT]", "configurations: [default]"),
     "spec/capabilities.yaml", "ra/ra", "configurations ['default'] differ from the model's"),
    # a registered fault without a site in the code
    (("cpp/runtime/lc/src/wayside/centre_scheduler.cpp", "RAILPROOF_FAULT(FAULT_LC_DEPART_WITHOUT_ALL_ACKS)",
      "false"),
     "spec/capabilities.yaml", "FAULT_LC_DEPART_WITHOUT_ALL_ACKS", "no RAILPROOF_FAULT(FAULT_LC_DEPART_WITHOUT_ALL_ACKS)"),
    # a fault site that is not registered
    (("cpp/runtime/lc/src/wayside/centre_scheduler.cpp", "RAILPROOF_FAULT(FAULT_LC_DEPART_WITHOUT_ALL_ACKS)",
      "RAILPROOF_FAULT(FAULT_LC_NEW)"),
     "cpp/runtime/lc/src", "FAULT_LC_NEW", "seeded fault not registered under lc"),
    # a fault named after another area
    (("spec/capabilities.yaml", "id: FAULT_LC_STALE_CONFIRMATION", "id: FAULT_MB_STALE_CONFIRMATION"),
     "spec/capabilities.yaml", "FAULT_MB_STALE_CONFIRMATION", "a fault of lc is named FAULT_<area>_"),
    # a fault of the units' glue without a site in cpp/runtime/units/src, and one of another area
    (("spec/capabilities.yaml", "units:\n  title: The on-board and wayside units\n  faults:\n",
      "units:\n  title: The on-board and wayside units\n  faults:\n"
      "    - {id: FAULT_UNIT_NOWHERE, text: no site, killed_by: [unit]}\n"),
     "spec/capabilities.yaml", "FAULT_UNIT_NOWHERE", "no RAILPROOF_FAULT(FAULT_UNIT_NOWHERE) in cpp/runtime/units/src"),
    (("spec/capabilities.yaml", "units:\n  title: The on-board and wayside units\n  faults:\n",
      "units:\n  title: The on-board and wayside units\n  faults:\n"
      "    - {id: FAULT_TG_GLUE, text: misnamed, killed_by: [unit]}\n"),
     "spec/capabilities.yaml", "FAULT_TG_GLUE", "a fault of units is named FAULT_<area>_... (UNIT)"),
    # a fault site in the units' glue that is not registered
    (("cpp/runtime/units/src/onboard/onboard_unit.cpp", "RAILPROOF_FAULT(FAULT_UNIT_REAR_FOR_FRONT)",
      "RAILPROOF_FAULT(FAULT_UNIT_NEW)"),
     "cpp/runtime/units/src", "FAULT_UNIT_NEW", "seeded fault not registered under units"),
    # a name that is not the first area in lower case
    (("spec/capabilities.yaml", "  - name: ra\n", "  - name: rx\n"),
     "spec/capabilities.yaml", "rx", "the name must be the lower-case first area (ra)"),
    # an area claimed twice
    (("spec/capabilities.yaml", "areas: [LC]", "areas: [LC, SC]"),
     "spec/capabilities.yaml", "lc", "area SC belongs to two capabilities"),
    # the registry says proofs, the tree has none (and the reverse below)
    (("spec/capabilities.yaml", "  - name: ra\n", "  - name: ra\n    proofs: true\n"),
     "proofs/ra", "ra", "missing: the registry says the capability has proofs"),
])
def test_every_disagreement_is_named(cli, repo, change, file, entry, fragment):
    rel, old, new = change
    edit(repo / rel, old, new)
    r = _check(cli, repo)
    assert r.rc == 1
    assert any(ln.startswith(f"{file}: {entry}: ") and fragment in ln for ln in r.lines), r.err


@pytest.mark.parametrize("rel, what", [
    ("spec/requirements/xx.yaml", "requirement of no registered capability"),
    ("spec/parameters/xx.yaml", "parameter of no registered capability"),
    ("spec/schemas/vectors_xx.schema.json", "vector schema of no registered capability"),
    ("models/xx.pml", "model of no registered capability"),
    ("cpp/runtime/xx/src/a.cpp", "cpp/runtime module of no registered capability"),
    ("cpp/offline/xx/src/a.cpp", "cpp/offline module of no registered capability"),
])
def test_a_file_of_no_capability_is_an_orphan(cli, repo, rel, what):
    p = repo / rel
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text("{}\n", encoding="utf-8")
    r = _check(cli, repo)
    assert r.rc == 1
    orphan = "/".join(Path(rel).parts[:3]) if rel.startswith("cpp/") else rel
    assert any(ln.startswith(f"{orphan}: -: ") and what in ln for ln in r.lines), r.err


def test_missing_files_of_a_capability_are_named(cli, repo):
    (repo / "spec/design/mb.md").unlink()
    (repo / "evidence/templates/lc.rst.jinja").unlink()
    r = _check(cli, repo)
    assert r.rc == 1
    assert r.has("spec/design/mb.md", "mb", "missing: design note")
    assert r.has("evidence/templates/lc.rst.jinja", "lc", "missing: evidence chapter")


def test_a_malformed_registry_names_the_entry(cli, repo):
    edit(repo / "spec/capabilities.yaml", "killed_by: [vectors, unit]}", "killed_by: [magic]}")
    r = _check(cli, repo)
    assert r.rc == 1
    assert "spec/capabilities.yaml: capabilities/0/faults/0/killed_by/0:" in r.err


def test_a_missing_schema_is_a_clear_error(cli, repo):
    (repo / "spec/schemas/capabilities.schema.json").unlink()
    r = _check(cli, repo)
    assert r.rc == 1
    assert "spec/schemas/capabilities.schema.json: -: file not found" in r.err
