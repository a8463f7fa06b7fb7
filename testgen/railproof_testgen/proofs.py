"""SMT-LIB2 proof obligations generated from spec/ and replayed by z3 and cvc5.

Command ``proofs --spec DIR --proofs DIR --out DIR [--timeout S] [--jobs N]``.

Every capability directory ``PROOFS/<cap>/`` holding obligation templates
(``*.smt2.in``; plain ``*.smt2`` files are templates without placeholders) gives
``OUT/<cap>.json`` and the generated obligations ``OUT/<cap>/<name>.smt2``; each is decided
by z3 and by cvc5 (Python APIs, one subprocess per run, so a hung solver is killed at the
time limit) and both verdicts must equal the expected one.

Template syntax (``;`` comment lines starting with ``@`` are directives, never copied):

- ``@obligation <NAME> REQ-… : text`` opens an obligation (the first one of a file is its
  base, read by ``railproof_testgen trace`` like every proof tag); ``@expect sat|unsat``;
  ``@instances once|trains`` (base only: ``trains`` gives one instance per train type of
  ``spec/trains/*.yaml``, named ``<NAME>.<train>``; the negative-test types in
  ``spec/trains/mutants/`` are not instantiated);
- later ``@obligation`` entries of the same file are variants of the base: the same text
  with every ``@mutate "old" -> "new"`` applied (each ``old`` must occur exactly once in
  the expanded text), e.g. a deliberately wrong obligation with one term removed;
- ``@solver <z3|cvc5> key=value …``: solver options for every obligation of the file;
- ``{{include FILE}}`` inserts ``PROOFS/<cap>/FILE`` (a template without obligations);
- ``{{AREA.id}}`` is the value of parameter ``id`` of ``spec/parameters/*.yaml`` with that
  ``area``; ``{{train.path}}`` a value of the instance's train type (dotted YAML path, list
  items by index, e.g. ``train.braking.emergency_free_running_ms.1``);
  ``{{trains.<name>.path}}`` one of a named train type; ``|real`` renders the number as an
  SMT-LIB decimal (``200.0``), otherwise as a numeral; negative values as ``(- n)``.

Lemmas (``define-fun lemma_… … Bool``, closed: only their parameters and SMT-LIB
operators): an obligation whose only assertion is ``(not (lemma_X c…))`` over distinct
declared constants proves lemma_X; one asserting ``(lemma_X …)`` uses it (cut rule). Every
used lemma must be proved by an obligation of the run whose definition of it is textually
identical, and a using obligation meets its target only if the proving one does.

Non-vacuity: the claim of an ``@expect unsat`` obligation is its last assertion, which must
be ``(assert (not …))``; the obligation without it (``OUT/<cap>/hypotheses/<name>.smt2``)
must be satisfiable: one solver finds a model, the other confirms it with every declared
constant fixed to the model's value (``<name>.witness.smt2``). Otherwise the proof could be
vacuous and the obligation fails.

Results ``OUT/<cap>.json`` (written atomically; schema ``railproof/proofs/1``)::

    {"schema", "capability", "requirements": [...], "verdict": "pass"|"fail",
     "solvers": {"z3": {"version", "package", "interface", "options"}, "cvc5": {...}},
     "timeout_s", "inputs": {path: sha256}, "summary": {...},
     "obligations": [{"name", "obligation", "instance", "source", "smt2", "sha256",
                      "requirements", "text", "expected", "mutations", "uses",
                      "options", "z3": {"verdict", "time_s", "wall_s", "model"?,
                      "reason"?}, "cvc5": {...}, "hypotheses"?: {"witness", "confirmed_by",
                      "time_s", "model"?, "reason"?}, "agree", "meets_target", "problem"?}]}

``time_s`` is the solver's check time, ``wall_s`` the subprocess wall time (start-up and
parsing included). Exit status 1 with a one-line reason on a solver disagreement, an
unexpected verdict, unknown or timeout, a failed lemma or unshown hypotheses (the JSON is
still written, with verdict "fail"), or bad input (``file: entry: reason``, nothing written). Progress goes to stderr.
"""
from __future__ import annotations

import hashlib
import json
import os
import re
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

from . import SPEC_DIR, add_command
from .errors import PipelineError, SpecError
from .files import write_atomic

SCHEMA = "railproof/proofs/1"
SOLVERS = ("z3", "cvc5")
PACKAGES = {"z3": "z3-solver", "cvc5": "cvc5"}
VERDICTS = ("sat", "unsat")
DEFAULT_TIMEOUT_S = 60.0
HYP_DIR = "hypotheses"  # OUT/<cap>/hypotheses/: the unsat obligations without their claims
KILL_GRACE_S = 10.0
MAX_INCLUDE_DEPTH = 8

_DIRECTIVE = re.compile(r"^\s*;+\s*@(\w[\w-]*)\b(.*)$")
_PLACEHOLDER = re.compile(r"\{\{\s*(.*?)\s*\}\}")
_INCLUDE = re.compile(r"^include\s+([A-Za-z0-9_.\-]+)$")
_REF = re.compile(r"^([A-Za-z_][\w]*(?:\.[\w]+)*)(?:\s*\|\s*(\w+))?$")
_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_MUTATE = re.compile(r'^\s*("(?:[^"\\]|\\.)*")\s*->\s*("(?:[^"\\]|\\.)*")\s*$')
_DECLARED = re.compile(r"\(declare-(?:const|fun)\s+([^\s()]+)")

# Values the obligations divide by or rely on being positive; every other value they use
# must be non-negative (a negative time, deceleration, margin or error is a spec error).
POSITIVE = {
    "BR.gravity_mm_s2", "BR.cycle_ms",
    "train.length_mm", "train.accel_max_mm_s2",
    "train.braking.emergency_pattern_mm_s2", "train.braking.service_pattern_mm_s2",
    "train.uncertainty.emergency_deceleration_mm_s2.0",
    "train.uncertainty.emergency_deceleration_mm_s2.1",
    "train.uncertainty.service_deceleration_mm_s2.0",
    "train.uncertainty.service_deceleration_mm_s2.1",
}


# ------------------------------------------------------------------ templates ----
@dataclass
class Obligation:
    name: str
    requirements: list
    text: str
    line: int
    expect: str | None = None
    mutations: list = field(default_factory=list)  # [(old, new)]


@dataclass
class Template:
    path: Path
    rel: str
    body: list  # source lines, directives removed (numbered for messages)
    obligations: list
    instances: str = "once"
    options: dict = field(default_factory=lambda: {s: {} for s in SOLVERS})


@dataclass
class Instance:
    name: str
    obligation: Obligation
    template: Template
    train: str | None
    text: str = ""
    smt2: str = ""
    uses: dict = field(default_factory=dict)  # lemma -> definition text
    proves: dict = field(default_factory=dict)
    use_names: list = field(default_factory=list)  # instance names of the proving obligations
    hyp: str | None = None  # '@expect unsat' only: the text without its claim


def _parse_template(path: Path, rel: str, known_reqs):
    """Read directives; returns Template (obligations empty for an include-only file)."""
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except UnicodeDecodeError:
        raise SpecError(rel, "-", "not UTF-8 text") from None
    t = Template(path=path, rel=rel, body=[], obligations=[])
    instances_seen = False
    for n, line in enumerate(lines, 1):
        m = _DIRECTIVE.match(line)
        if not m:
            t.body.append((n, line))
            continue
        tag, rest = m.group(1), m.group(2).strip()
        entry = f"line {n}"
        cur = t.obligations[-1] if t.obligations else None
        if tag == "obligation":
            head, sep, text = rest.partition(" : ")
            parts = head.split()
            if not sep or not parts or not _NAME.match(parts[0]) or parts[0].startswith("REQ-"):
                raise SpecError(rel, entry, "expected '@obligation <NAME> REQ-… : text'")
            reqs = parts[1:]
            if not reqs:
                raise SpecError(rel, f"@obligation {parts[0]}", "names no requirement")
            for r in reqs:
                if r not in known_reqs:
                    raise SpecError(rel, f"@obligation {parts[0]}",
                                    f"unknown requirement {r}")
            t.obligations.append(Obligation(parts[0], reqs, text.strip(), n))
        elif tag == "expect":
            if cur is None:
                raise SpecError(rel, entry, "@expect before any @obligation")
            if rest not in VERDICTS:
                raise SpecError(rel, f"@obligation {cur.name}",
                                f"@expect must be 'sat' or 'unsat', got {rest!r}")
            if cur.expect is not None:
                raise SpecError(rel, f"@obligation {cur.name}", "@expect given twice")
            cur.expect = rest
        elif tag == "instances":
            if cur is None or len(t.obligations) != 1 or instances_seen:
                raise SpecError(rel, entry, "@instances belongs to the first obligation, once")
            if rest not in ("once", "trains"):
                raise SpecError(rel, f"@obligation {cur.name}",
                                f"@instances must be 'once' or 'trains', got {rest!r}")
            t.instances, instances_seen = rest, True
        elif tag == "mutate":
            if cur is None or len(t.obligations) < 2:
                raise SpecError(rel, entry, "@mutate belongs to a variant (a later @obligation)")
            mm = _MUTATE.match(rest)
            if not mm:
                raise SpecError(rel, f"@obligation {cur.name}",
                                'expected \'@mutate "old" -> "new"\'')
            old, new = json.loads(mm.group(1)), json.loads(mm.group(2))
            if not old:
                raise SpecError(rel, f"@obligation {cur.name}", "@mutate: empty pattern")
            cur.mutations.append((old, new))
        elif tag == "solver":
            parts = rest.split()
            if not parts or parts[0] not in SOLVERS:
                raise SpecError(rel, entry, f"@solver needs one of {', '.join(SOLVERS)}")
            for kv in parts[1:]:
                k, sep, v = kv.partition("=")
                if not sep or not k or not v:
                    raise SpecError(rel, entry, f"@solver option {kv!r} is not key=value")
                t.options[parts[0]][k] = v
        elif tag == "verifies":
            raise SpecError(rel, entry, "use '@obligation <NAME> REQ-… : text' in templates")
        else:
            raise SpecError(rel, entry, f"unknown directive @{tag}")
    while t.body and re.match(r"^\s*;*\s*$", t.body[0][1]):
        t.body.pop(0)  # the empty comment lines that separated the directives
    for i, ob in enumerate(t.obligations):
        if ob.expect is None:
            raise SpecError(rel, f"@obligation {ob.name}", "missing '@expect sat|unsat'")
        if i > 0 and not ob.mutations:
            raise SpecError(rel, f"@obligation {ob.name}",
                            "a variant needs at least one @mutate (or its own file)")
    return t


# ------------------------------------------------------------------ spec data ----
class SpecValues:
    """Lookup of {{...}} references in the validated spec, with value checks."""

    def __init__(self, spec_dir: Path, model):
        self.spec_dir = Path(spec_dir)
        self.params = {}  # area -> (file, {id: value})
        for area, data in model["parameters"].items():
            self.params[area] = (data["file"], {pid: e["value"]
                                                for pid, e in data["parameters"].items()})
        self.trains = dict(sorted(model.get("trains", {}).items()))
        self.train_files = {n: self.spec_dir / "trains" / f"{n}.yaml" for n in self.trains}
        self.used = {}  # file -> sha256 of every spec file a value came from

    def _note(self, f):
        f = Path(f)
        if str(f) not in self.used:
            self.used[str(f)] = hashlib.sha256(f.read_bytes()).hexdigest()

    def lookup(self, ref, train, where):
        rel, entry = where
        parts = ref.split(".")
        head = parts[0]
        if head in self.params:
            if len(parts) != 2:
                raise SpecError(rel, entry, f"{{{{{ref}}}}}: expected AREA.parameter_id")
            f, values = self.params[head]
            if parts[1] not in values:
                raise SpecError(rel, entry, f"{{{{{ref}}}}}: no parameter {parts[1]!r} in "
                                            f"{Path(f).name} (area {head})")
            value = values[parts[1]]
            self._check(ref, value, f, parts[1])
            self._note(f)
            return value
        if head == "train":
            if train is None:
                raise SpecError(rel, entry, f"{{{{{ref}}}}}: 'train.' needs '@instances trains'")
            name, path = train, parts[1:]
            check_key = "train." + ".".join(path)
        elif head == "trains":
            if len(parts) < 3:
                raise SpecError(rel, entry, f"{{{{{ref}}}}}: expected trains.<name>.<path>")
            name, path = parts[1], parts[2:]
            check_key = "train." + ".".join(path)
        else:
            raise SpecError(rel, entry, f"{{{{{ref}}}}}: unknown reference (expected AREA.id, "
                                        "train.… or trains.<name>.…)")
        if name not in self.trains:
            raise SpecError(rel, entry, f"{{{{{ref}}}}}: no train type {name!r} in "
                                        f"{self.spec_dir / 'trains'}")
        f = self.train_files.get(name, self.spec_dir / "trains" / f"{name}.yaml")
        obj = self.trains[name]
        shown = []
        for p in path:
            if isinstance(obj, list) and p.isdigit() and int(p) < len(obj):
                obj = obj[int(p)]
                shown[-1] = f"{shown[-1]}[{p}]" if shown else f"[{p}]"
            elif isinstance(obj, dict) and p in obj:
                obj = obj[p]
                shown.append(p)
            else:
                raise SpecError(f, name, f"no value {'.'.join(path)} (used by {rel})")
        self._note(f)
        if path == ["name"]:
            return obj
        self._check(check_key, obj, f, ".".join(shown))
        return obj

    @staticmethod
    def _check(key, value, f, entry):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise SpecError(f, entry, f"must be a number, got {value!r}")
        if key in POSITIVE and not value > 0:
            raise SpecError(f, entry, f"must be positive for the proof obligations, "
                                      f"got {value}")
        if value < 0:
            raise SpecError(f, entry, f"must not be negative for the proof obligations, "
                                      f"got {value}")


def _render(value, fmt, where):
    rel, entry = where
    if isinstance(value, str):
        if fmt or not re.match(r"^[A-Za-z0-9_]+$", value):
            raise SpecError(rel, entry, f"value {value!r} cannot be used here")
        return value
    if fmt not in (None, "real", "int"):
        raise SpecError(rel, entry, f"unknown format |{fmt} (expected |real or |int)")
    if fmt == "int" and not (isinstance(value, int) or float(value).is_integer()):
        raise SpecError(rel, entry, f"value {value} is not an integer")
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    if isinstance(value, int):
        text = f"{abs(value)}.0" if fmt == "real" else str(abs(value))
    else:
        if fmt != "real":
            raise SpecError(rel, entry, f"value {value} is not an integer; use |real")
        text = repr(abs(value))
        if "e" in text or "E" in text:
            text = f"{abs(value):.17f}".rstrip("0")
    return f"(- {text})" if value < 0 else text


# ------------------------------------------------------------- s-expressions ----
_BUILTINS = {"and", "or", "not", "=>", "=", "<=", "<", ">=", ">", "+", "-", "*", "/", "ite",
             "to_real", "to_int", "is_int", "abs", "div", "mod", "distinct", "xor", "true",
             "false", "Real", "Int", "Bool"}
_NUMERAL = re.compile(r"^\d+(\.\d+)?$")


def _strip_comments(text):
    return "\n".join(ln.split(";", 1)[0] for ln in text.splitlines())


def _sexprs(code, where):
    """Top-level s-expressions of SMT-LIB code as nested lists of atoms."""
    tokens = re.findall(r"\(|\)|[^\s()]+", code)
    stack = [[]]
    for tok in tokens:
        if tok == "(":
            stack.append([])
        elif tok == ")":
            if len(stack) == 1:
                raise SpecError(*where, "unbalanced ')' in the SMT-LIB text")
            done = stack.pop()
            stack[-1].append(done)
        else:
            stack[-1].append(tok)
    if len(stack) != 1:
        raise SpecError(*where, "unbalanced '(' in the SMT-LIB text")
    return stack[0]


def _atoms(t):
    if isinstance(t, list):
        for x in t:
            yield from _atoms(x)
    else:
        yield t


def _unparse(t):
    return "(" + " ".join(_unparse(x) for x in t) + ")" if isinstance(t, list) else t


def _top_level_spans(text):
    """(start, end) of every top-level parenthesised form in SMT-LIB text (comments
    skipped)."""
    spans, depth, start, i = [], 0, None, 0
    while i < len(text):
        c = text[i]
        if c == ";":
            j = text.find("\n", i)
            i = len(text) if j < 0 else j
            continue
        if c == "(":
            if depth == 0:
                start = i
            depth += 1
        elif c == ")":
            depth -= 1
            if depth == 0:
                spans.append((start, i + 1))
        i += 1
    return spans


def _hypotheses_only(text, where):
    """The obligation without its claim (its last assertion, which must be a negation):
    the solvers must find it satisfiable, else the proof would be vacuous."""
    asserts = [(a, b) for a, b in _top_level_spans(text)
               if re.match(r"\(\s*assert\b", text[a:b])]
    if not asserts:
        raise SpecError(*where, "no assertion")
    a, b = asserts[-1]
    if not re.match(r"\(\s*assert\s+\(\s*not\b", text[a:b]):
        raise SpecError(*where, "the claim (the last assertion) of an '@expect unsat' "
                                "obligation must be '(assert (not …))'")
    return text[:a] + "; (claim removed: the hypotheses alone must be satisfiable)" + text[b:]


# ------------------------------------------------------------------ generation ----
class Generator:
    def __init__(self, spec_dir, proofs_dir, values: SpecValues, known_requirements,
                 repo_root=None):
        self.known_requirements = set(known_requirements)
        self.sources = {}  # template/include path (relative) -> sha256
        self.spec_dir = Path(spec_dir)
        self.proofs_dir = Path(proofs_dir)
        self.values = values
        self.root = Path(repo_root) if repo_root else self.proofs_dir.resolve().parent

    def parse(self, path, known):
        rel = self.rel(path)
        self.sources[rel] = hashlib.sha256(Path(path).read_bytes()).hexdigest()
        return _parse_template(path, rel, known)

    def rel(self, p):
        try:
            return Path(p).resolve().relative_to(self.root.resolve()).as_posix()
        except ValueError:
            return Path(p).as_posix()

    def expand(self, cap_dir: Path, tmpl: Template, train, depth=0, stack=()):
        out = []
        for n, line in tmpl.body:
            where = (tmpl.rel, f"line {n}")
            m = _PLACEHOLDER.search(line)
            if m and _INCLUDE.match(m.group(1).strip()):
                if line.strip() != m.group(0):
                    raise SpecError(*where, "{{include FILE}} must stand alone on its line")
                fname = _INCLUDE.match(m.group(1).strip()).group(1)
                inc_path = cap_dir / fname
                if not inc_path.is_file():
                    raise SpecError(*where, f"included file {fname} not found in {cap_dir}")
                if fname in stack or depth >= MAX_INCLUDE_DEPTH:
                    raise SpecError(*where, f"recursive include of {fname}")
                inc = self.parse(inc_path, self.known_requirements)
                if inc.obligations:
                    raise SpecError(*where, f"included file {fname} declares obligations")
                out.append(self.expand(cap_dir, inc, train, depth + 1, stack + (fname,)))
                continue

            def sub(mm, where=where):
                ref = mm.group(1).strip()
                rm = _REF.match(ref)
                if not rm:
                    raise SpecError(*where, f"malformed placeholder {{{{{ref}}}}}")
                value = self.values.lookup(rm.group(1), train, where)
                return _render(value, rm.group(2), where)

            text = _PLACEHOLDER.sub(sub, line)
            if "{{" in text or "}}" in text:
                raise SpecError(*where, "unbalanced '{{' or '}}'")
            out.append(text)
        return "\n".join(out)

    def instances(self, cap_dir: Path):
        """All obligation instances of one capability, in a deterministic order."""
        cap_dir = Path(cap_dir)
        known = self.known_requirements
        templates = []
        for p in sorted(list(cap_dir.glob("*.smt2.in")) + list(cap_dir.glob("*.smt2"))):
            t = self.parse(p, known)
            if t.obligations:
                templates.append(t)
        out, names = [], {}
        for t in templates:
            trains = list(self.values.trains) if t.instances == "trains" else [None]
            if t.instances == "trains" and not trains:
                raise SpecError(self.spec_dir / "trains", "-", "no train types (*.yaml)")
            for train in trains:
                base = self.expand(cap_dir, t, train)
                for ob in t.obligations:
                    text = base
                    for old, new in ob.mutations:
                        k = text.count(old)
                        if k != 1:
                            raise SpecError(t.rel, f"@obligation {ob.name}",
                                            f"@mutate pattern {old!r} occurs {k} times in the "
                                            "expanded text (expected exactly once)")
                        text = text.replace(old, new)
                    name = ob.name + (f".{train}" if train else "")
                    if ob.name in names and names[ob.name] != t.rel:
                        raise SpecError(t.rel, f"@obligation {ob.name}",
                                        f"name also used in {names[ob.name]}")
                    names[ob.name] = t.rel
                    inst = Instance(name=name, obligation=ob, template=t, train=train)
                    inst.text = text
                    inst.smt2 = self._header(inst) + text.strip("\n") + "\n"
                    if ob.expect == "unsat":
                        inst.hyp = _hypotheses_only(
                            inst.smt2.replace("; expected verdict: unsat",
                                              "; expected verdict: sat (hypotheses only)", 1),
                            (t.rel, f"@obligation {ob.name}"))
                    self._lemmas(inst)
                    out.append(inst)
        self._link_lemmas(out)
        return out

    def _header(self, inst):
        ob = inst.obligation
        lines = [f"; Generated by railproof_testgen proofs from {inst.template.rel}; do not edit.",
                 f"; obligation {inst.name}: {' '.join(ob.requirements)}",
                 f";   {ob.text}",
                 f"; expected verdict: {ob.expect}"
                 + (" (UNSAT proves the claim)" if ob.expect == "unsat"
                    else " (a counterexample exists)")]
        if inst.train:
            lines.append(f"; train type: {inst.train}")
        for old, new in ob.mutations:
            lines.append(f"; mutation: {json.dumps(old)} -> {json.dumps(new)}")
        return "\n".join(lines) + "\n"

    def _lemmas(self, inst):
        """Find the lemmas an instance proves (its only assertion is the negation of the
        lemma over distinct declared constants) and uses (asserted instances)."""
        where = (inst.template.rel, f"@obligation {inst.obligation.name}")
        forms = _sexprs(_strip_comments(inst.text), where)
        declared = {f[1] for f in forms if isinstance(f, list) and len(f) > 1
                    and f[0] in ("declare-const", "declare-fun") and isinstance(f[1], str)}
        defs = {f[1]: f for f in forms if isinstance(f, list) and len(f) == 5
                and f[0] == "define-fun" and isinstance(f[1], str)}
        asserts = [f[1] for f in forms if isinstance(f, list) and len(f) == 2
                   and f[0] == "assert"]

        def lemma_call(t):
            return isinstance(t, list) and t and isinstance(t[0], str) \
                and t[0].startswith("lemma_")

        for a in asserts:
            if isinstance(a, list) and len(a) == 2 and a[0] == "not" and lemma_call(a[1]):
                name, args = a[1][0], a[1][1:]
                ok = (inst.obligation.expect == "unsat" and len(asserts) == 1
                      and all(isinstance(x, str) and x in declared for x in args)
                      and len(set(args)) == len(args))
                if not ok:
                    raise SpecError(*where, f"an obligation proving {name} must be '@expect "
                                            "unsat' and assert nothing but its negation over "
                                            "distinct declared constants")
                inst.proves[name] = self._lemma_definition(defs, name, where)
            elif lemma_call(a):
                inst.uses[a[0]] = self._lemma_definition(defs, a[0], where)

    @staticmethod
    def _lemma_definition(defs, name, where):
        """Canonical text of a closed lemma definition (only its parameters, numerals and
        SMT-LIB operators occur in its body, so equal text means the same lemma)."""
        d = defs.get(name)
        if d is None:
            raise SpecError(*where, f"{name} is asserted but not defined")
        _df, _n, params, sort, body = d
        if sort != "Bool" or not isinstance(params, list) or not all(
                isinstance(p, list) and len(p) == 2 and isinstance(p[0], str) for p in params):
            raise SpecError(*where, f"{name} must be a define-fun with parameters returning "
                                    "Bool")
        names = {p[0] for p in params}
        free = sorted({t for t in _atoms(body) if t not in names and t not in _BUILTINS
                       and not _NUMERAL.match(t)})
        if free:
            raise SpecError(*where, f"{name} refers to {', '.join(free)}; a lemma may use "
                                    "only its parameters (closed definition)")
        return _unparse(d)

    @staticmethod
    def _link_lemmas(instances):
        provers = {}
        for inst in instances:
            for lemma, d in inst.proves.items():
                provers.setdefault((lemma, d), []).append(inst.name)
        for inst in instances:
            for lemma, d in sorted(inst.uses.items()):
                who = provers.get((lemma, d))
                if not who:
                    raise SpecError(inst.template.rel, f"@obligation {inst.obligation.name}",
                                    f"uses {lemma} but no obligation proves this definition "
                                    "of it (assert its negation in an @expect unsat obligation)")
                inst.use_names.extend(n for n in who if n not in inst.use_names)


def load_spec(spec_dir):
    from .validate import validate_spec
    spec_dir = Path(spec_dir)
    model = validate_spec(spec_dir)
    return model, SpecValues(spec_dir, model)


def generate(spec_dir, proofs_dir, out_dir):
    """Generate every capability's obligations into OUT/<cap>/. Returns (caps, inputs):
    {cap: [Instance]} and {path: sha256} of every spec file and template used."""
    spec_dir, proofs_dir, out_dir = Path(spec_dir), Path(proofs_dir), Path(out_dir)
    if not proofs_dir.is_dir():
        raise SpecError(proofs_dir, "-", "proofs directory not found")
    model, values = load_spec(spec_dir)
    gen = Generator(spec_dir, proofs_dir, values, model["requirements"])
    caps = {}
    for cap_dir in sorted(p for p in proofs_dir.iterdir() if p.is_dir()):
        insts = gen.instances(cap_dir)
        if insts:
            caps[cap_dir.name] = insts
    for cap, insts in caps.items():
        d = out_dir / cap
        d.mkdir(parents=True, exist_ok=True)
        wanted = set()
        for inst in insts:
            path = d / f"{inst.name}.smt2"
            wanted.add(path.name)
            write_atomic(path, inst.smt2)
        hyp_dir = d / HYP_DIR
        if hyp_dir.is_dir():
            for old in hyp_dir.glob("*.smt2"):
                old.unlink()
        for inst in insts:
            if inst.hyp is not None:
                hyp_dir.mkdir(exist_ok=True)
                write_atomic(hyp_dir / f"{inst.name}.smt2", inst.hyp)
        logs = {f"{Path(w).stem}.{s}.log" for w in wanted for s in SOLVERS}
        for stale in list(d.glob("*.smt2")) + list(d.glob("*.log")):
            if stale.name not in wanted and stale.name not in logs:
                stale.unlink()
    inputs = {}
    for f, h in values.used.items():
        inputs[gen.rel(f)] = h
    inputs.update(gen.sources)
    return caps, dict(sorted(inputs.items()))


# --------------------------------------------------------------------- solving ----
def _worker_env():
    env = dict(os.environ)
    pkg_parent = str(Path(__file__).resolve().parents[1])
    env["PYTHONPATH"] = pkg_parent + (os.pathsep + env["PYTHONPATH"]
                                      if env.get("PYTHONPATH") else "")
    return env


def run_solver(solver, smt2_path, timeout_s, options=None):
    """Decide one .smt2 file with one solver in a subprocess. Returns a dict with verdict
    (sat, unsat, unknown, timeout, error), time_s, wall_s, version, package, model
    (sat only), reason (unknown/timeout/error)."""
    cmd = [sys.executable, "-m", "railproof_testgen.proofs", "--worker", solver,
           str(smt2_path), str(int(timeout_s * 1000)), json.dumps(options or {})]
    t0 = time.perf_counter()
    try:
        cp = subprocess.run(cmd, capture_output=True, text=True, env=_worker_env(),
                            timeout=timeout_s + KILL_GRACE_S)
    except subprocess.TimeoutExpired:
        return {"verdict": "timeout", "time_s": None,
                "wall_s": round(time.perf_counter() - t0, 3),
                "reason": f"no answer within {timeout_s:g} s (killed)"}
    wall = round(time.perf_counter() - t0, 3)
    lines = [ln for ln in cp.stdout.splitlines() if ln.startswith("{")]
    if cp.returncode != 0 or not lines:
        err = (cp.stderr.strip().splitlines() or ["no output"])[-1]
        return {"verdict": "error", "time_s": None, "wall_s": wall,
                "reason": f"solver process failed (exit {cp.returncode}): {err}"}
    res = json.loads(lines[-1])
    res["wall_s"] = wall
    return res


def _worker(solver, path, timeout_ms, options):
    """Runs inside the subprocess; prints one JSON line."""
    from importlib import metadata
    text = Path(path).read_text(encoding="utf-8")
    out = {"package": f"{PACKAGES[solver]}=={metadata.version(PACKAGES[solver])}"}
    if solver == "z3":
        import z3
        out["version"] = z3.get_version_string()
        options = dict(options)
        tactic = options.pop("tactic", None)
        if tactic:  # e.g. simplify,propagate-values,solve-eqs,smt
            names = tactic.split(",")
            s = (z3.Then(*names) if len(names) > 1 else z3.Tactic(names[0])).solver()
        else:
            s = z3.Solver()
        s.set("timeout", int(timeout_ms))
        for k, v in options.items():
            s.set(k, _option_value(v))
        s.from_string(text)
        t0 = time.perf_counter()
        r = s.check()
        out["time_s"] = round(time.perf_counter() - t0, 4)
        out["verdict"] = "sat" if r == z3.sat else "unsat" if r == z3.unsat else "unknown"
        if r == z3.sat:
            m = s.model()
            declared = set(_DECLARED.findall(text))  # not the define-fun macros
            out["model"] = {d.name(): _z3_value(m[d]) for d in
                            sorted(m.decls(), key=lambda d: d.name())
                            if d.arity() == 0 and d.name() in declared}
        elif r != z3.unsat:
            reason = s.reason_unknown()
            out["reason"] = reason
            if "timeout" in reason or "canceled" in reason:
                out["verdict"] = "timeout"
    else:
        import cvc5
        tm = cvc5.TermManager()
        s = cvc5.Solver(tm)
        out["version"] = _text(s.getVersion())
        s.setOption("produce-models", "true")
        s.setOption("tlimit-per", str(int(timeout_ms)))
        for k, v in options.items():
            s.setOption(k, str(v))
        sm = cvc5.SymbolManager(tm)
        parser = cvc5.InputParser(s, sm)
        parser.setStringInput(cvc5.InputLanguage.SMT_LIB_2_6, text, Path(path).name)
        while True:
            cmd = parser.nextCommand()
            if cmd.isNull():
                break
            if cmd.getCommandName() in ("check-sat", "get-model", "exit"):
                continue
            cmd.invoke(s, sm)
        t0 = time.perf_counter()
        r = s.checkSat()
        out["time_s"] = round(time.perf_counter() - t0, 4)
        if r.isSat():
            out["verdict"] = "sat"
            terms = [t for t in sm.getDeclaredTerms() if not t.getSort().isFunction()]
            out["model"] = {str(t): str(s.getValue(t)) for t in
                            sorted(terms, key=lambda t: str(t))}
        elif r.isUnsat():
            out["verdict"] = "unsat"
        else:
            reason = str(r.getUnknownExplanation())
            out["verdict"] = "timeout" if "TIMEOUT" in reason else "unknown"
            out["reason"] = reason
    print(json.dumps(out, sort_keys=True))


def _text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def _option_value(v):
    return {"true": True, "false": False}.get(v, int(v) if str(v).isdigit() else v)


def _z3_value(v):
    import z3
    if z3.is_algebraic_value(v):
        return v.as_decimal(12)
    return str(v)


# --------------------------------------------------------------------- results ----
def _judge(inst, res):
    """(agree, meets_target, problem) of one instance's own results (lemmas aside)."""
    exp = inst.obligation.expect
    vz, vc = res["z3"]["verdict"], res["cvc5"]["verdict"]
    for s in SOLVERS:
        v = res[s]["verdict"]
        if v not in VERDICTS:
            why = res[s].get("reason") or v
            return vz == vc and vz in VERDICTS, False, f"{inst.name}: {s} gave {v} ({why})"
    if vz != vc:
        return False, False, f"{inst.name}: solvers disagree (z3 {vz}, cvc5 {vc})"
    if vz != exp:
        return True, False, f"{inst.name}: both solvers {vz}, expected {exp}"
    if exp == "sat":
        for s in SOLVERS:
            if not res[s].get("model"):
                return True, False, f"{inst.name}: {s} returned sat without a model"
    return True, True, None


def replay(caps, out_dir, timeout_s=DEFAULT_TIMEOUT_S, jobs=2, inputs=None, solver=None,
           progress=None):
    """Run both solvers on every instance; write OUT/<cap>.json. Returns [problems]."""
    out_dir = Path(out_dir)
    progress = progress or sys.stderr
    run = solver or run_solver
    tasks = [(cap, inst, s) for cap, insts in caps.items() for inst in insts for s in SOLVERS]
    tasks += [(cap, inst, "hypotheses") for cap, insts in caps.items() for inst in insts
              if inst.hyp is not None]
    results = {}
    total = len(tasks)
    done = [0]

    def work(task):
        cap, inst, s = task
        if s == "hypotheses":
            return task, _witness(run, out_dir / cap / HYP_DIR, inst, timeout_s)
        path = out_dir / cap / f"{inst.name}.smt2"
        res = run(s, path, timeout_s, inst.template.options.get(s, {}))
        return task, res

    with ThreadPoolExecutor(max_workers=max(1, jobs)) as ex:
        for (cap, inst, s), res in ex.map(work, tasks):
            results[(cap, inst.name, s)] = res
            done[0] += 1
            t = res.get("time_s")
            what = res["verdict"] if s != "hypotheses" else (
                f"satisfiable (model of {res['witness']}, confirmed by {res['confirmed_by']})"
                if res.get("confirmed_by") else "NOT shown satisfiable")
            print(f"proofs: [{done[0]}/{total}] {inst.name}: {s} {what}"
                  + (f" in {t:.3f} s" if isinstance(t, (int, float)) else ""),
                  file=progress, flush=True)
    problems_all = []
    for cap, insts in caps.items():
        rows, problems = [], []
        by_name = {}
        for inst in insts:
            res = {s: results[(cap, inst.name, s)] for s in SOLVERS}
            agree, ok, problem = _judge(inst, res)
            row = {"name": inst.name, "obligation": inst.obligation.name,
                   "instance": inst.train, "source": inst.template.rel,
                   "smt2": f"{cap}/{inst.name}.smt2",
                   "sha256": hashlib.sha256(inst.smt2.encode()).hexdigest(),
                   "requirements": list(inst.obligation.requirements),
                   "text": inst.obligation.text, "expected": inst.obligation.expect,
                   "mutations": [{"old": o, "new": n} for o, n in inst.obligation.mutations],
                   "uses": list(inst.use_names),
                   "options": {s: dict(inst.template.options.get(s, {})) for s in SOLVERS},
                   "agree": agree, "meets_target": ok}
            for s in SOLVERS:
                row[s] = {k: v for k, v in res[s].items()
                          if k in ("verdict", "time_s", "wall_s", "model", "reason")}
            if inst.hyp is not None:
                hyp = results[(cap, inst.name, "hypotheses")]
                row["hypotheses"] = hyp
                if ok and not hyp.get("confirmed_by"):
                    ok = row["meets_target"] = False
                    problem = (f"{inst.name}: its hypotheses were not shown satisfiable "
                               f"({hyp.get('reason')}); the proof could be vacuous")
            if problem:
                row["problem"] = problem
            rows.append(row)
            by_name[inst.name] = row
        for row in rows:  # an obligation resting on a failed lemma fails too
            bad = [u for u in row["uses"] if not by_name[u]["meets_target"]]
            if bad and row["meets_target"]:
                row["meets_target"] = False
                row["problem"] = f"{row['name']}: uses lemma obligation(s) that failed: " \
                                 + ", ".join(bad)
        rows.sort(key=lambda r: r["name"])
        problems = [r["problem"] for r in rows if not r["meets_target"]]
        problems_all.extend(problems)
        versions = {}
        for s in SOLVERS:
            seen = {(r.get("version"), r.get("package")) for (c, _n, ss), r in results.items()
                    if c == cap and ss == s and r.get("version")}
            v = sorted(seen)[0] if seen else (None, None)
            versions[s] = {"version": v[0], "package": v[1],
                           "interface": "Python API, one subprocess per obligation",
                           "default_options": {"timeout_ms": int(timeout_s * 1000)}
                           if s == "z3" else {"tlimit-per": int(timeout_s * 1000),
                                              "produce-models": "true"}}
        times = {s: round(sum((r[s].get("time_s") or 0) for r in rows), 4) for s in SOLVERS}
        reqs = sorted({r for inst in insts for r in inst.obligation.requirements})
        data = {
            "schema": SCHEMA, "capability": cap, "requirements": reqs,
            "verdict": "pass" if not problems else "fail",
            "solvers": versions, "timeout_s": timeout_s,
            "inputs": dict(sorted((inputs or {}).items())),
            "summary": {"obligations": len(rows),
                        "expected_unsat": sum(r["expected"] == "unsat" for r in rows),
                        "expected_sat": sum(r["expected"] == "sat" for r in rows),
                        "met": sum(r["meets_target"] for r in rows),
                        "failed": sum(not r["meets_target"] for r in rows),
                        "solver_time_s": times},
            "obligations": rows,
        }
        if problems:
            data["problems"] = problems
        write_atomic(out_dir / f"{cap}.json",
                     json.dumps(data, indent=2, sort_keys=True, ensure_ascii=False) + "\n", if_changed=False)
        _write_logs(out_dir / cap, rows)
    return problems_all


def _witness(run, hyp_dir, inst, timeout_s):
    """Non-vacuity of an '@expect unsat' obligation: one solver finds a model of its
    hypotheses (the obligation without its claim), the other confirms that model (the
    hypotheses with every declared constant fixed to the model's value)."""
    path = hyp_dir / f"{inst.name}.smt2"
    sorts = _declared_sorts(inst.hyp)
    tried = []
    t_total = 0.0
    for first, second in (("z3", "cvc5"), ("cvc5", "z3")):
        opts = inst.template.options
        res = run(first, path, timeout_s, opts.get(first, {}))
        t_total += res.get("time_s") or 0.0
        tried.append(f"{first} {res['verdict']}")
        if res["verdict"] == "unsat":
            return {"witness": None, "confirmed_by": None, "time_s": round(t_total, 4),
                    "reason": f"{first}: the hypotheses are unsatisfiable"}
        if res["verdict"] != "sat" or not res.get("model"):
            continue
        fixed = _fix_model(res["model"], sorts)
        if fixed is None:
            tried.append(f"{first} model not exact")
            continue
        wpath = hyp_dir / f"{inst.name}.witness.smt2"
        write_atomic(wpath, inst.hyp.rstrip("\n").rsplit("(check-sat)", 1)[0]
                     + f"; the model of {first}\n" + fixed + "(check-sat)\n", if_changed=False)
        conf = run(second, wpath, timeout_s, opts.get(second, {}))
        t_total += conf.get("time_s") or 0.0
        tried.append(f"{second} on the model {conf['verdict']}")
        if conf["verdict"] == "sat":
            return {"witness": first, "confirmed_by": second, "time_s": round(t_total, 4),
                    "model": res["model"]}
    return {"witness": None, "confirmed_by": None, "time_s": round(t_total, 4),
            "reason": "; ".join(tried)}


def _declared_sorts(text):
    forms = _sexprs(_strip_comments(text), ("-", "-"))
    out = {}
    for f in forms:
        if isinstance(f, list) and len(f) == 3 and f[0] == "declare-const":
            out[f[1]] = f[2]
        elif isinstance(f, list) and len(f) == 4 and f[0] == "declare-fun" and f[2] == []:
            out[f[1]] = f[3]
    return out


def _fix_model(model, sorts):
    """SMT-LIB assertions fixing every declared constant to its model value; None if a
    value is not exact (an approximated algebraic number)."""
    lines = []
    for name, sort in sorted(sorts.items()):
        if name not in model:
            continue
        text = str(model[name]).strip()
        if sort == "Bool":
            if text.lower() not in ("true", "false"):
                return None
            lines.append(f"(assert (= {name} {text.lower()}))")
            continue
        if "?" in text:
            return None
        try:
            value = _eval_number(_sexprs(text, ("-", "-"))[0])
        except (ValueError, ZeroDivisionError, IndexError, TypeError):
            return None
        if sort == "Int":
            if value.denominator != 1:
                return None
            lit = str(abs(value.numerator))
        else:
            lit = f"(/ {abs(value.numerator)}.0 {value.denominator}.0)"
        lines.append(f"(assert (= {name} {'(- ' + lit + ')' if value < 0 else lit}))")
    return "".join(ln + "\n" for ln in lines)


def _eval_number(t):
    if isinstance(t, str):
        return Fraction(t)
    if t and t[0] == "-" and len(t) == 2:
        return -_eval_number(t[1])
    if t and t[0] == "/" and len(t) == 3:
        return _eval_number(t[1]) / _eval_number(t[2])
    raise ValueError(str(t))


def _write_logs(d: Path, rows):
    """Per obligation and solver a log in SMT-LIB output style (verdict, then the model)."""
    for row in rows:
        for s in SOLVERS:
            r = row[s]
            lines = [r["verdict"]]
            if r.get("reason"):
                lines.append(f"; reason: {r['reason']}")
            if r.get("time_s") is not None:
                lines.append(f"; solver time: {r['time_s']} s")
            for k, v in (r.get("model") or {}).items():
                lines.append(f"; {k} = {v}")
            write_atomic(d / f"{row['name']}.{s}.log", "\n".join(lines) + "\n", if_changed=False)


# --------------------------------------------------------------------- command ----
def run(args):
    out = Path(args.out)
    caps, inputs = generate(args.spec, args.proofs, out)
    if not caps:
        raise SpecError(args.proofs, "-", "no obligation templates (*.smt2.in) found")
    n = sum(len(v) for v in caps.values())
    print(f"proofs: {n} obligation(s) generated in {out} "
          f"({', '.join(f'{c}: {len(v)}' for c, v in caps.items())})", file=sys.stderr)
    problems = replay(caps, out, timeout_s=args.timeout, jobs=args.jobs, inputs=inputs)
    for cap in caps:
        data = json.loads((out / f"{cap}.json").read_text(encoding="utf-8"))
        s = data["summary"]
        print(f"proofs: {cap}: {s['met']}/{s['obligations']} as expected "
              f"(z3 {s['solver_time_s']['z3']:.2f} s, cvc5 {s['solver_time_s']['cvc5']:.2f} s "
              f"solver time) -> {out / (cap + '.json')}")
    if problems:
        more = f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""
        raise PipelineError(f"proofs: {problems[0]}{more}")
    return 0


def register(sub):
    add_command(sub, "proofs", run,
                "generate the SMT proof obligations and replay them with z3 and cvc5",
                """Generate every obligation of PROOFS/<capability>/*.smt2.in from the spec
                parameters and train types into OUT/<capability>/, decide each with z3 and
                cvc5, and write OUT/<capability>.json. Exit 1 on a disagreement, an unexpected
                verdict, unknown or timeout, or bad input.""",
                spec=SPEC_DIR, proofs="proofs/ directory (templates)",
                out="output directory (build/results/proofs)",
                timeout={"type": float, "default": DEFAULT_TIMEOUT_S,
                         "help": f"time limit per solver and obligation in s (default "
                                 f"{DEFAULT_TIMEOUT_S:g})"},
                jobs={"type": int, "default": 2, "help": "solver processes in parallel (default 2)"})



if __name__ == "__main__":
    if len(sys.argv) == 6 and sys.argv[1] == "--worker":
        _worker(sys.argv[2], sys.argv[3], int(sys.argv[4]), json.loads(sys.argv[5]))
    else:
        print("usage: python -m railproof_testgen.proofs --worker SOLVER FILE TIMEOUT_MS "
              "OPTIONS_JSON (internal; use 'python -m railproof_testgen proofs')",
              file=sys.stderr)
        sys.exit(2)
