"""The vector sets of a build, for the tests that check them. Those tests read the pipeline's
results and never regenerate the vectors: the environment variable RAILPROOF_RESULTS_DIR names
a build's results directory (ctest sets it); without it they are skipped. Also the check of a
capability's vector schema on hand-made records (check_schema_cases)."""
from __future__ import annotations

import copy
import json
import os
from pathlib import Path

import pytest
import yaml

from railproof_testgen import registry, spin, vectors
from railproof_testgen.errors import PipelineError

REPO = Path(__file__).resolve().parents[2]
RESULTS_VAR = "RAILPROOF_RESULTS_DIR"


class VectorSet:
    """<model>.jsonl and <model>.*.jsonl of a results directory, and <model>.coverage.json."""

    def __init__(self, vector_dir: Path, model: str):
        self.model = model
        self.path = REPO / "models" / f"{model}.pml"
        self.capability = registry.load(REPO / "spec").of_model(self.path).name
        names = [f"{model}.jsonl"] + sorted(p.name for p in vector_dir.glob(f"{model}.*.jsonl"))
        self.texts = {n: (vector_dir / n).read_text(encoding="utf-8") for n in names}
        self.files = {n: [json.loads(ln) for ln in text.splitlines()] for n, text in self.texts.items()}
        self.coverage = json.loads((vector_dir / f"{model}.coverage.json").read_text(encoding="utf-8"))

    def header(self, name: str) -> dict:
        return self.files[name][0]

    def vectors(self, name: str | None = None) -> list:
        """The vectors of one file, or of every file."""
        return [v for n, lines in self.files.items() if name in (None, n) for v in lines[1:]]

    def by_goal(self, name: str) -> dict:
        """{goal: vector} of one file (the first vector of each goal: tg's roles share a run)."""
        out = {}
        for v in self.vectors(name):
            if v["goal"]:
                out.setdefault(v["goal"], v)
        return out

    def justifications(self) -> dict:
        f = REPO / "spec" / "justifications" / f"{self.capability}.yaml"
        entries = yaml.safe_load(f.read_text(encoding="utf-8"))["justifications"] if f.is_file() else []
        return {e["goal"]: e["id"] for e in entries if e["model"] == f"models/{self.model}.pml"}

    def schema_validator(self):
        return vectors.schema_validator(REPO / "spec" / "schemas" / f"vectors_{self.capability}.schema.json")


def vector_set(model: str) -> VectorSet:
    """The build's vectors of models/<model>.pml; skips without RAILPROOF_RESULTS_DIR, fails
    when the directory it names lacks them."""
    results = os.environ.get(RESULTS_VAR)
    if not results:
        pytest.skip(f"{RESULTS_VAR} is not set: the checks of the generated vectors read a build's "
                    "results (ctest sets it to the build's results directory)")
    vector_dir = Path(results) / "vectors"
    for f in (vector_dir / f"{model}.jsonl", vector_dir / f"{model}.coverage.json"):
        if not f.is_file():
            pytest.fail(f"{f} is missing: generate the vectors first (build target results/vectors/{model}.jsonl)")
    return VectorSet(vector_dir, model)


def check_vector_set(vs: VectorSet):
    """What every vector set must satisfy: every file whole (its header's count and digest
    match its vector lines), every line schema-valid, headers naming the model as it is now, unique ids, every goal reached with vectors in the files or unreachable with the
    justification spec/justifications gives it, and a coverage record that counts the files."""
    validator = vs.schema_validator()
    ids = set()
    for name, lines in vs.files.items():
        assert len(lines) > 1, f"{name}: no vectors"
        assert vectors.check_seal(vs.texts[name], name) == lines[0]
        for n, obj in enumerate(lines, 1):
            errors = list(validator.iter_errors(obj))
            assert not errors, f"{name} line {n}: {errors[0].message}"
        header = lines[0]
        assert header["kind"] == "header" and header["model"] == f"models/{vs.model}.pml", name
        assert header["model_sha256"] == spin.sha256_file(vs.path), f"{name}: generated from another model"
        for v in lines[1:]:
            assert v["id"] not in ids, f"{name}: duplicate id {v['id']}"
            ids.add(v["id"])
    ann = spin.parse_annotations(vs.path)
    cov = vs.coverage
    assert [g["id"] for g in cov["goals"]] == [g.gid for g in ann.goals]
    assert cov["labelled"] == len(ann.goals) and cov["model"] == f"models/{vs.model}.pml"
    justified = vs.justifications()
    for g in cov["goals"]:
        if g["status"] == "reached":
            assert g["vectors"] and set(g["vectors"]) <= ids, g
            assert g["justification"] is None, g
        else:
            assert g["status"] == "unreachable" and g["states_searched"] > 0, g
            assert g["justification"] == justified[g["id"]], g
        assert set(g.get("variant_vectors", [])) <= ids, g
    assert set(justified) == {g["id"] for g in cov["goals"] if g["status"] == "unreachable"}
    assert cov["reached"] + cov["unreachable_justified"] == len(ann.goals)
    assert cov["files"] == {n: len(lines) - 1 for n, lines in vs.files.items()}
    assert cov["vectors"] == {k: sum(v["kind"] == k for v in vs.vectors()) for k in ("trap", "boundary", "random")}
    for name in vs.files:  # random walks: seeds 1..n in each file
        for tag in {v["id"].rsplit("S", 1)[0] for v in vs.vectors(name) if v["kind"] == "random"}:
            seeds = sorted({v["seed"] for v in vs.vectors(name) if v["id"].rsplit("S", 1)[0] == tag})
            assert seeds == list(range(1, len(seeds) + 1)), (name, tag)


def edited(records: list, edit) -> list:
    """A deep copy of records (the lines of a vector file) with edit applied to it."""
    lines = copy.deepcopy(records)
    edit(lines)
    return lines


def check_schema_cases(schema: Path, good: list, name: str, broken: dict):
    """The records good (a header and vectors) pass the vector schema unchanged as the file
    name (the header sealed with their count and digest); each edit of broken ({what: edit of a
    copy of good}) makes them fail it."""
    text = vectors.sealed_jsonl(schema, good[0], good[1:], name)
    assert [json.loads(ln) for ln in text.splitlines()] == [vectors.seal(good[0], text.partition("\n")[2]), *good[1:]]
    for what, edit in broken.items():
        with pytest.raises(PipelineError, match="violates the vector schema"):
            lines = edited(good, edit)
            vectors.sealed_jsonl(schema, lines[0], lines[1:], name)
            pytest.fail(f"schema accepted: {what}")
