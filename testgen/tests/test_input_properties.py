"""Property-based tests of the loader and the spec checker, with Hypothesis (settings and
generators: strategies.py).

The loader: any bytes give a document or one finding, never an exception of another kind;
any JSON document within the limits reads back equal from YAML and from JSON; the nesting,
string and alias limits refuse exactly what exceeds them. The checker: a parameter value
of any kind passes validate exactly when it has the type and lies in the range its unit
declares (spec/schemas/parameters.schema.json), and otherwise the finding names the file and
the parameter and gen-params writes nothing."""
from __future__ import annotations

import json
import math

import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from conftest import FIXTURES, REPO
from railproof_testgen import params, spec, validate
from railproof_testgen.errors import SpecError
from strategies import dump, json_documents, json_values, paths, replaced, spec_tree

SCHEMA = json.loads((REPO / "spec/schemas/parameters.schema.json").read_text(encoding="utf-8"))


def _load(kind, text):
    with spec_tree({f"data.{kind}": text}) as root:
        return (spec.load_yaml if kind == "yaml" else spec.load_json)(root / f"data.{kind}")


# --------------------------------------------------------------------------- the loader

@pytest.mark.parametrize("kind", ["yaml", "json"])
@given(data=st.binary(max_size=1000))
def test_any_bytes_give_a_document_or_one_finding(kind, data):
    with spec_tree() as root:
        path = root / f"data.{kind}"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
        try:
            doc = (spec.load_yaml if kind == "yaml" else spec.load_json)(path)
        except SpecError as exc:
            assert exc.file == str(path) and exc.entry and exc.reason
        else:
            assert isinstance(doc, dict)


@given(text=st.text(alphabet="{}[]:,-&*!|>'\"#%@`?<=~\n\t .0123456789eExyz", max_size=300))
def test_any_yaml_like_text_gives_a_document_or_one_finding(text):
    try:
        doc = _load("yaml", text)
    except SpecError as exc:
        assert exc.entry and exc.reason
    else:
        assert isinstance(doc, dict)


@given(doc=json_documents)
def test_any_document_within_the_limits_reads_back_equal(doc):
    assert _load("yaml", yaml.safe_dump(doc)) == doc
    assert _load("json", json.dumps(doc)) == doc


@given(depth=st.integers(0, 2 * spec.MAX_DEPTH))
def test_nesting_is_refused_exactly_beyond_the_depth_limit(depth):
    # the top-level mapping is one level, each list one more
    for kind, text in (("yaml", "a: " + "[" * depth + "0" + "]" * depth + "\n"),
                       ("json", '{"a": ' + "[" * depth + "0" + "]" * depth + "}")):
        if 1 + depth <= spec.MAX_DEPTH:
            assert _load(kind, text) is not None
        else:
            with pytest.raises(SpecError, match=f"nested deeper than {spec.MAX_DEPTH} levels"):
                _load(kind, text)


@given(n=st.integers(spec.MAX_STRING - 2, spec.MAX_STRING + 2))
def test_strings_are_refused_exactly_beyond_the_length_limit(n):
    for kind, text in (("yaml", f"a: {'x' * n}\n"), ("json", json.dumps({"a": "x" * n}))):
        if n <= spec.MAX_STRING:
            assert _load(kind, text) == {"a": "x" * n}
        else:
            with pytest.raises(SpecError, match=f"exceeds the limit of {spec.MAX_STRING}"):
                _load(kind, text)


@given(n=st.integers(spec.MAX_ALIASES - 2, spec.MAX_ALIASES + 2))
def test_aliases_are_refused_exactly_beyond_their_limit(n):
    text = "a: &a [1, 2]\nb: [" + ", ".join(["*a"] * n) + "]\n"
    if n <= spec.MAX_ALIASES:
        assert _load("yaml", text)["b"] == [[1, 2]] * n
    else:
        with pytest.raises(SpecError, match=f"more than {spec.MAX_ALIASES} aliases"):
            _load("yaml", text)


# --------------------------------------------------------------------------- the checker

VALID = FIXTURES / "spec_valid/spec"
SPEC_FILES = sorted(str(p.relative_to(VALID)) for p in VALID.rglob("*.yaml"))


@given(data=st.data())
def test_no_value_anywhere_in_a_spec_file_makes_validate_raise(data):
    """Any field of any file of a valid spec tree replaced by any JSON value: validate
    reports findings (or none), it never raises."""
    rel = data.draw(st.sampled_from(SPEC_FILES))
    doc = yaml.safe_load((VALID / rel).read_text(encoding="utf-8"))
    text = dump(replaced(doc, data.draw(st.sampled_from(paths(doc))), data.draw(json_values)))
    with spec_tree({rel: text}, {".": VALID, "schemas": REPO / "spec/schemas"}) as tree:
        validate.check_spec(tree)



def _quantity(unit):
    """(type, minimum, maximum) the parameter schema declares for a unit."""
    for rule in SCHEMA["$defs"]["quantity"]["allOf"]:
        if unit in rule["if"]["properties"]["unit"]["enum"]:
            q = SCHEMA["$defs"][rule["then"]["properties"]["value"]["$ref"].rsplit("/", 1)[1]]
            return q["type"], q["minimum"], q["maximum"]
    raise AssertionError(f"unit {unit!r} has no quantity")


def _accepted(value, kind, lo, hi):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    if kind == "integer" and not isinstance(value, int):
        return False
    return math.isfinite(value) and lo <= value <= hi


UNITS = SCHEMA["$defs"]["unit"]["enum"]


def values(lo, hi):
    return st.one_of(st.integers(-(1 << 70), 1 << 70), st.floats(), st.booleans(),
                     st.text(max_size=4), st.none(),
                     st.sampled_from([lo - 1, lo, hi, hi + 1, lo + 0.5, float(lo), hi * 1.0001]))


@given(data=st.data(), bound=st.booleans())
def test_a_parameter_passes_exactly_when_its_unit_admits_it(data, bound):
    unit = data.draw(st.sampled_from(UNITS))
    kind, lo, hi = _quantity(unit)
    if bound:  # a model bound is a Promela int as well
        kind, lo, hi = "integer", max(lo, 0), min(hi, (1 << 31) - 1)
    value = data.draw(values(lo, hi))
    entry = {"id": "p", "value": value, "unit": unit}
    entry.update({"rationale": "generated"} if bound
                 else {"source": "ASM-001", "requirements": ["REQ-TG-001"]})
    doc = {"schema": "railproof/parameters/1", "area": "TG",
           "parameters": [{"id": "q", "value": 1, "unit": "bit", "source": "ASM-001",
                           "requirements": ["REQ-TG-001"]}]}
    doc.setdefault("model_bounds" if bound else "parameters", []).append(entry)
    with spec_tree({"parameters/tg.yaml": dump(doc)},
                   {"requirements": FIXTURES / "spec_valid/spec/requirements",
                    "hazards": FIXTURES / "spec_valid/spec/hazards",
                    "assumptions": FIXTURES / "spec_valid/spec/assumptions",
                    "justifications": FIXTURES / "spec_valid/spec/justifications",
                    "schemas": REPO / "spec/schemas"}) as tree:
        _model, report = validate.check_spec(tree)
        findings = [f for f in report.errors if f.file.endswith("parameters/tg.yaml")]
        out = tree.parent / "gen"
        if _accepted(value, kind, lo, hi):
            assert findings == [], findings
            params.generate(tree, out)
            header = (out / "include/railproof/generated/tg_params.hpp").read_text(encoding="utf-8")
            assert "inline constexpr auto p = " in header
        else:
            assert any(f.entry in ("p", "parameters[p].value", "model_bounds[p].value")
                       for f in findings), findings
            with pytest.raises(SpecError):
                params.generate(tree, out)
            assert not out.exists()
