"""Mechanical traceability check: every requirement to its models, vectors, code and tests.

Command ``trace --spec DIR --src REPO_ROOT --results RESULTS_DIR --out trace.json
[--allow-missing-results]``.

Link sources (paths relative to REPO_ROOT unless noted):
- ``models/**/*.pml`` annotations ``// @property <ltl> REQ-… : text``,
  ``// @goal <K> REQ-… : label`` and ``// @mutant <NAME> violates <ltl> : text``;
- ``RESULTS_DIR/spin/*.json`` (spec/design/tg.md §8): a property verifies its
  requirements only with verdict ``verified``; every mutant must be ``rejected``;
- ``RESULTS_DIR/vectors/*.jsonl`` (header line, then vectors with ``id`` and
  ``requirements``) and ``*.coverage.json`` (goal coverage; an ``unreachable`` goal needs a
  justification from ``spec/justifications/*.yaml`` written for that goal and model);
- C++ tags ``@implements REQ-…`` and ``@verifies REQ-…``. An ``@implements`` under
  ``cpp/runtime/<module>/{include,src}`` is a runtime code unit (link ``code``); one under
  ``cpp/offline/<module>/{include,src,tools}`` is an offline tool unit (link ``tool``), which
  never counts as the implementation of a runtime requirement. An ``@verifies`` in a test
  (a ``tests/``, ``conformance/`` or ``fuzz/`` folder, with the ``TEST(...)`` that follows)
  is a test link (``unit``);
- ``proofs/**`` tags ``@verifies REQ-…`` and ``@obligation <name> REQ-… : text``;
- ``RESULTS_DIR/analysis/*.json`` with a top-level ``"requirements": [...]`` list.

Errors (exit 1): a dangling or malformed reference anywhere; a property ``violated`` or
``incomplete``; a mutant that survived; an unreachable goal without a matching
justification; an empty vector set; a requirement whose verification method X has no link
of kind X (model: a verified property; vectors: a vector; unit: a ``@verifies`` test;
analysis: an analysis result; proof: an obligation); a SIL-4 runtime requirement (the
default ``implemented_by: runtime``) without an ``@implements`` unit under ``cpp/runtime``
unless it is verified by analysis alone; a requirement ``implemented_by: offline`` without
an ``@implements`` unit under ``cpp/offline``.  With
``--allow-missing-results`` a missing results directory (and the links only it could
supply) is a warning, so the check can run before the pipeline has produced results.
Stale results (a property, mutant or goal in the results that no annotation names) are
errors; a ``model_sha256`` that differs from the model file in the source tree is a
warning.  Goal ids: the model's ``@goal 17`` and the coverage's ``"G17"`` are the same goal.

Output (deterministic: sorted keys and lists, paths relative to REPO_ROOT or to
RESULTS_DIR, no time stamps)::

    {"schema": "railproof/trace/1",
     "requirements": [{"id", "area", "capability", "title", "sil", "source", "hazards", "verification",
                       "implemented_by": "runtime" | "offline",
                     "links": {"model": [{"property", "verdict", "model"}],
                                 "goals": ["G17", ...], "vectors": ["TG-TRAP-017", ...],
                                 "unit": [{"file", "test"}], "code": [{"file", "unit"}],
                                 "tool": [{"file", "unit"}],
                                 "analysis": ["analysis/residual_error.json"],
                                 "proof": [{"file", "obligation"}]},
                       "status": "ok" | "error", "problems": ["file: entry: reason"]}],
     "goals": [{"goal", "model", "label", "requirements", "status", "vector",
                "justification"}],
     "errors": [...], "warnings": [...], "summary": {...counts...}}
"""
from __future__ import annotations

import hashlib
import json
import re
import sys
from pathlib import Path

from . import SPEC_DIR, add_command
from . import registry as registry_mod
from .errors import SpecError
from .files import write_atomic
from .spec import jsonl_records
from .checks import REQ_ID, Report
from .validate import check_spec

SCHEMA = "railproof/trace/1"
LINK_KINDS = ("model", "goals", "vectors", "unit", "code", "tool", "analysis", "proof")
# verification method -> the link kind that satisfies it
METHOD_LINK = {"model": "model", "vectors": "vectors", "unit": "unit",
               "analysis": "analysis", "proof": "proof"}
# link kinds that only results (not sources) can supply
RESULT_KINDS = {"model": "spin", "vectors": "vectors", "analysis": "analysis"}

CPP_SUFFIXES = {".cpp", ".cc", ".cxx", ".hpp", ".hh", ".hxx", ".h", ".ipp", ".inl"}
# cpp/<kind>/<module>/<part>/...: runtime code, offline tools, tests (by the folder names)
_CODE_PATH = re.compile(r"^cpp/(runtime|offline)/[^/]+/(include|src|tools)/")
_TEST_PATH = re.compile(r"^cpp/.*/(tests|conformance|fuzz)/")
FAILED_VERDICTS = {"fail", "failed", "violated", "error"}

# Tags open a comment: prose that merely mentions "@implements" is not a tag, and the
# usage examples inside a model's /* ... */ header are not either.
_MODEL_TAG = re.compile(r"^\s*//+\s*@(property|goal|mutant|assert)\b(.*)$")
_CPP_TAG = re.compile(r"(?:^\s*\*+|//+|/\*+)\s*@(implements|verifies)\b(.*)$")
_PROOF_TAG = re.compile(r"(?:^\s*\*+|;+|#+|//+|/\*+)\s*@(verifies|obligation)\b(.*)$")
_TEST_MACRO = re.compile(
    r"^\s*(TEST|TEST_F|TEST_P|TYPED_TEST|TYPED_TEST_P|FUZZ_TEST)\s*\(\s*(\w+)\s*,\s*(\w+)")
_CLASS = re.compile(r"^\s*(?:template\s*<.*>\s*)?(?:class|struct|union|enum(?:\s+class)?)\s+"
                    r"(?:\[\[[^\]]*\]\]\s*)?([A-Za-z_]\w*)")
_FUNC = re.compile(r"([A-Za-z_~][\w:~]*(?:operator\s*\S+?)?)\s*\(")
_NOT_A_UNIT = {"if", "for", "while", "switch", "return", "sizeof", "static_assert",
               "decltype", "alignof", "noexcept", "requires", "template"}


def _goal_id(k):
    """Goal ids: the model's numeric K and the coverage's "G<K>" name the same goal."""
    k = str(k).strip()
    return f"G{k}" if k.isdigit() else k


def _tagged(lines, pattern):
    """(line number, line, match) of every line that pattern matches."""
    for n, line in enumerate(lines, 1):
        m = pattern.search(line)
        if m:
            yield n, line, m


class Tracer:
    def __init__(self, spec_dir, src, results, allow_missing):
        self.spec_dir = Path(spec_dir)
        self.src = Path(src)
        self.results = Path(results)
        self.allow_missing = allow_missing
        self.report = Report()
        self.model = None
        self.links = {}
        self.problems = {}
        self.missing = set()  # result kinds whose directory is missing (allowed)
        self.properties = {}  # name -> {"requirements", "files", "line", "results": []}
        self.goals = {}  # goal id -> {"requirements", "label", "model", "status", ...}
        self.mutants = {}  # name -> {"property", "file", "line", "verdict"}
        self.vectors = {}  # id -> file
        self.used_justifications = set()
        self.counts = {"vectors": 0, "analysis_results": 0}
        self.test_set, self.unit_set, self.obligation_set = set(), set(), set()

    # ----------------------------------------------------------------- helpers ----
    def rel(self, path):
        """Stable display path: results files relative to RESULTS_DIR, everything else
        relative to REPO_ROOT (absolute only if outside both)."""
        path = Path(path)
        for base in (self.results, self.src):
            try:
                return path.resolve().relative_to(base.resolve()).as_posix()
            except ValueError:
                continue
        return path.as_posix()

    def error(self, file, entry, reason, reqs=()):
        f = self.report.error(self.rel(file) if isinstance(file, Path) else file, entry, reason)
        for r in reqs:
            if r in self.problems and str(f) not in self.problems[r]:
                self.problems[r].append(str(f))
        return f

    def warn(self, file, entry, reason):
        return self.report.warn(self.rel(file) if isinstance(file, Path) else file, entry, reason)

    def missing_result(self, path, kind, what):
        shown = f"{self.results.name}/{Path(path).relative_to(self.results).as_posix()}"
        if self.allow_missing:
            self.missing.add(kind)
            self.warn(shown, "-", f"{what} (allowed by --allow-missing-results)")
        else:
            self.error(shown, "-", what)

    def parse_ids(self, file, entry, text):
        """Requirement IDs at the start of text (space/comma separated); errors for
        malformed or unknown ones. Returns (known ids, rest of the text, number of
        REQ-like tokens seen)."""
        ids, rest = [], text
        tokens = re.split(r"[\s,;]+", text.strip())
        consumed = 0
        for tok in tokens:
            tok_clean = tok.rstrip(".)*/")
            if not tok_clean.startswith("REQ-"):
                break
            consumed += 1
            self._collect_id(file, entry, tok_clean, ids)
        rest = " ".join(tokens[consumed:])
        return ids, rest, consumed

    def check_req_list(self, file, entry, lst):
        """A requirements list from a results file; returns the known ids."""
        if not isinstance(lst, list) or not all(isinstance(x, str) for x in lst):
            self.error(file, entry, "'requirements' must be a list of requirement ids")
            return []
        ids = []
        for r in lst:
            self._collect_id(file, entry, r, ids)
        return ids

    def _collect_id(self, file, entry, rid, ids):
        """Append rid to ids (once) if it names a known requirement; an error if it is
        malformed or unknown."""
        if not REQ_ID.match(rid):
            self.error(file, entry, f"malformed requirement id {rid!r}")
        elif rid not in self.model["requirements"]:
            self.error(file, entry, f"dangling reference: unknown requirement {rid}")
        elif rid not in ids:
            ids.append(rid)

    def add(self, rid, kind, item):
        lst = self.links[rid][kind]
        if item not in lst:
            lst.append(item)

    @staticmethod
    def read_lines(path):
        try:
            return path.read_text(encoding="utf-8").splitlines()
        except UnicodeDecodeError:
            return None

    def result_files(self, sub, pattern="*.json"):
        """(RESULTS_DIR/sub, its files matching pattern, sorted; none if it is missing)."""
        d = self.results / sub
        return d, sorted(d.glob(pattern)) if d.is_dir() else []

    def load_object(self, path, key):
        """The JSON object of a results file that holds a list under key, or None (after an
        error)."""
        data = self.load_json(path)
        if data is None:
            return None
        if not isinstance(data, dict) or not isinstance(data.get(key), list):
            article = "an" if key[0] in "aeiou" else "a"
            self.error(path, "-", f"expected an object with {article} '{key}' list")
            return None
        return data

    def load_json(self, path):
        try:
            return json.loads(path.read_text(encoding="utf-8"))
        except json.JSONDecodeError as exc:
            self.error(path, f"line {exc.lineno}", f"malformed JSON: {exc.msg}")
        except UnicodeDecodeError:
            self.error(path, "-", "not UTF-8 text")
        return None

    # ------------------------------------------------------------------ models ----
    def scan_models(self):
        files = sorted((self.src / "models").rglob("*.pml"))
        for f in files:
            for n, line, m in _tagged(self.read_lines(f) or [], _MODEL_TAG):
                tag, body = m.group(1), m.group(2).strip()
                body = re.sub(r"\*/\s*$", "", body).strip()
                head, sep, text = body.partition(" : ")
                if not sep and body.endswith(":"):
                    head, text = body[:-1], ""
                parts = head.split(None, 1)
                if not parts or (tag != "mutant" and len(parts) < 2):
                    self.error(f, f"line {n}", f"malformed @{tag} tag: {line.strip()!r}")
                    continue
                name = parts[0]
                entry = f"@{tag} {_goal_id(name) if tag == 'goal' else name} (line {n})"
                if tag == "mutant":
                    self._model_mutant(f, n, entry, name, parts[1] if len(parts) > 1 else "",
                                       text.strip())
                    continue
                ids, leftover, seen = self.parse_ids(f, entry, parts[1])
                if leftover:
                    self.error(f, entry, f"unexpected text {leftover!r} before ' : ' "
                                         "(expected requirement ids)")
                elif not seen:
                    self.error(f, entry, "tag names no requirement")
                if tag == "property":
                    self._model_property(f, n, entry, name, ids, text.strip())
                elif tag == "assert":
                    # a named model assertion: checked in every verification run of its
                    # model; mutants may name it as "assert:<label>"
                    self._model_property(f, n, entry, f"assert:{name}", ids, text.strip())
                    self.properties[f"assert:{name}"]["assertion"] = True
                else:
                    self._model_goal(f, n, entry, _goal_id(name), ids, text.strip())
        for name, mu in sorted(self.mutants.items()):
            if mu["property"] not in self.properties:
                self.error(mu["file"], f"@mutant {name} (line {mu['line']})",
                           f"dangling reference: no @property named {mu['property']}")
        text = "\n".join("\n".join(self.read_lines(f) or []) for f in files)
        for name, p in sorted(self.properties.items()):
            if p.get("assertion"):
                continue
            if not re.search(rf"\bltl\s+{re.escape(name)}\b", text):
                self.warn(p["files"][0], f"@property {name}",
                          "no 'ltl' formula with this name in models/")

    def _model_property(self, f, n, entry, name, ids, text):
        p = self.properties.get(name)
        if p is None:
            self.properties[name] = {"requirements": ids, "files": [self.rel(f)], "line": n,
                                     "text": text, "results": []}
        elif sorted(p["requirements"]) != sorted(ids):
            self.error(f, entry, f"property already annotated in {p['files'][0]} with other "
                                 f"requirements {sorted(p['requirements'])}")
        elif self.rel(f) not in p["files"]:
            p["files"].append(self.rel(f))
        else:
            self.error(f, entry, "property annotated twice in the same model")

    def _model_goal(self, f, n, entry, gid, ids, label):
        key = (self.rel(f), gid)
        if key in self.goals:
            self.error(f, entry, "goal annotated twice in the same model")
            return
        self.goals[key] = {"goal": gid, "model": self.rel(f), "requirements": ids,
                           "label": label, "line": n, "status": "missing", "vector": None,
                           "justification": None, "covered": False}

    def _model_mutant(self, f, n, entry, name, rest, text):
        m = re.match(r"^violates\s+(\S+)\s*$", rest)
        if not m:
            self.error(f, entry, "expected '@mutant <NAME> violates <ltl name> : text'")
            return
        if name in self.mutants:
            self.error(f, entry, f"mutant already annotated in {self.mutants[name]['file']}")
            return
        self.mutants[name] = {"property": m.group(1), "file": self.rel(f), "line": n,
                              "text": text, "verdict": "missing"}

    # ------------------------------------------------------------- SPIN results ----
    def scan_spin(self):
        d, files = self.result_files("spin")
        if not files:
            if self.properties or self.mutants or self._needs("model"):
                self.missing_result(d, "model", "no model-checking results (spin/*.json)")
            return
        seen_mutants = set()
        for f in files:
            data = self.load_object(f, "properties")
            if data is None:
                continue
            model_path = self._model_ref(f, "model", data)
            if model_path is None:
                model_path = "?"
            for i, p in enumerate(data["properties"]):
                self._spin_property(f, i, p, model_path)
            # named model assertions (// @assert): checked in every verification run
            for i, a in enumerate(data.get("assertions") or []):
                self._spin_property(f, i, a, model_path)
            mutants = data.get("mutants", [])
            if not isinstance(mutants, list):
                self.error(f, "mutants", "must be a list")
                mutants = []
            for i, mu in enumerate(mutants):
                name = self._spin_mutant(f, i, mu)
                if name:
                    seen_mutants.add(name)
        for name, p in sorted(self.properties.items()):
            if not p["results"] and not p.get("assertion"):
                self.error(p["files"][0], f"@property {name} (line {p['line']})",
                           "property has no model-checking result", p["requirements"])
        for name, mu in sorted(self.mutants.items()):
            if name not in seen_mutants:
                reqs = self.properties.get(mu["property"], {}).get("requirements", [])
                self.error(mu["file"], f"@mutant {name} (line {mu['line']})",
                           "mutant has no model-checking result", reqs)

    def _spin_property(self, f, i, p, model_path):
        if not isinstance(p, dict) or not isinstance(p.get("name"), str):
            self.error(f, f"properties[{i}]", "property needs a 'name'")
            return
        name = p["name"]
        entry = f"property {name}"
        ids = self.check_req_list(f, entry, p.get("requirements", []))
        verdict = p.get("verdict")
        ann = self.properties.get(name)
        if ann is None:
            self.error(f, entry, "no @property annotation in models/ (stale results?)")
            ann = self.properties[name] = {"requirements": ids, "files": [model_path],
                                           "line": 0, "text": "", "results": [],
                                           "from_results": True}
        elif sorted(ids) != sorted(ann["requirements"]):
            self.error(f, entry, f"requirements {sorted(ids)} differ from the @property "
                                 f"annotation {sorted(ann['requirements'])}")
        reqs = sorted(set(ids) | set(ann["requirements"]))
        ann["requirements"] = reqs
        if verdict not in ("verified", "violated", "incomplete"):
            self.error(f, entry, f"unknown verdict {verdict!r}", reqs)
        elif verdict != "verified":
            self.error(f, entry, f"property {verdict}", reqs)
        ann["results"].append({"model": model_path, "verdict": verdict})

    def _spin_mutant(self, f, i, mu):
        if not isinstance(mu, dict) or not isinstance(mu.get("name"), str):
            self.error(f, f"mutants[{i}]", "mutant needs a 'name'")
            return None
        name = mu["name"]
        entry = f"mutant {name}"
        ann = self.mutants.get(name)
        prop = mu.get("property")
        if ann is None:
            self.error(f, entry, "no @mutant annotation in models/ (stale results?)")
            ann = self.mutants[name] = {"property": mu.get("property"), "file": self.rel(f),
                                        "line": 0, "text": "", "verdict": "missing"}
        elif prop is not None and prop != ann["property"]:
            self.error(f, entry, f"property {prop!r} differs from the annotation "
                                 f"({ann['property']})")
        prop = prop or (ann or {}).get("property")
        if prop and prop not in self.properties:
            self.error(f, entry, f"dangling reference: no property named {prop}")
        reqs = self.properties.get(prop, {}).get("requirements", []) if prop else []
        verdict = mu.get("verdict")
        if verdict != "rejected":
            what = "survived" if verdict == "survived" else f"has verdict {verdict!r}"
            self.error(f, entry, f"mutant {what}: the model checker did not reject it "
                                 f"(expected a violation of {prop})", reqs)
        ann["verdict"] = verdict if isinstance(verdict, str) else "missing"
        return name

    # ---------------------------------------------------------------- vectors ----
    def scan_vectors(self):
        d, files = self.result_files("vectors", "*.jsonl")
        if not files:
            self.missing_result(d, "vectors", "no vector files (vectors/*.jsonl): "
                                              "empty or missing vector set")
            return
        for f in files:
            self._vector_file(f)
        covs = sorted(d.glob("*.coverage.json"))
        if not covs and self.goals:
            self.error(d, "-", "no goal coverage files (vectors/*.coverage.json)")
        for f in covs:
            self._coverage_file(f)
        for (_model, gid), g in sorted(self.goals.items()):
            if not g["covered"]:
                self.error(g["model"], f"@goal {gid} (line {g['line']})",
                           "goal is missing from the coverage report", g["requirements"])

    def _vector_file(self, f):
        lines = self.read_lines(f)
        if lines is None:
            self.error(f, "-", "not UTF-8 text")
            return
        header = None
        count = 0
        for n, obj in jsonl_records(lines, lambda n, exc: self.error(f, f"line {n}",
                                                                     f"malformed JSON: {exc.msg}")):
            if header is None:
                header = obj
                if not isinstance(obj, dict) or obj.get("kind") != "header":
                    self.error(f, f"line {n}", "first line must be the header "
                                               "({\"kind\":\"header\",...})")
                else:
                    self._model_ref(f, "header", obj)
                continue
            if not isinstance(obj, dict) or not isinstance(obj.get("id"), str):
                self.error(f, f"line {n}", "vector needs an 'id'")
                continue
            vid = obj["id"]
            if vid in self.vectors:
                self.error(f, vid, f"duplicate vector id (also in {self.vectors[vid]})")
                continue
            self.vectors[vid] = self.rel(f)
            count += 1
            ids = self.check_req_list(f, vid, obj.get("requirements"))
            if not ids and isinstance(obj.get("requirements"), list) \
                    and not obj["requirements"]:
                self.warn(f, vid, "vector names no requirement")
            for r in ids:
                self.add(r, "vectors", vid)
        if count == 0:
            self.error(f, "-", "empty vector set (no vector after the header)")
        self.counts["vectors"] += count

    def _model_ref(self, f, entry, data):
        """The model a results file (or a vector header) names, or None: an error if it names
        none or one not in the source tree; a warning if it is of another model version."""
        model_path = data.get("model")
        if not isinstance(model_path, str):
            self.error(f, entry, "missing model path")
            return None
        if not (self.src / model_path).is_file():
            self.error(f, entry, f"dangling reference: model {model_path} not found")
        else:
            self._check_hash(f, data.get("model_sha256"), model_path)
        return model_path

    def _check_hash(self, f, sha, model_path):
        """Results from another version of the model are stale: warn (the hash is of the
        model source file as committed, see spec/design/tg.md §8)."""
        if not isinstance(sha, str):
            return
        actual = hashlib.sha256((self.src / model_path).read_bytes()).hexdigest()
        if sha != actual:
            self.warn(f, "model_sha256", f"differs from {model_path} in the source tree "
                                         "(results from another model version?)")

    def _coverage_file(self, f):
        data = self.load_object(f, "goals")
        if data is None:
            return
        model_path = data.get("model")
        if not isinstance(model_path, str):
            model_path = self._model_of_vectors(f)
        reached = 0
        just = self.model["justifications"]
        for i, g in enumerate(data["goals"]):
            if not isinstance(g, dict) or g.get("id") is None:
                self.error(f, f"goals[{i}]", "goal needs an 'id'")
                continue
            gid = _goal_id(g["id"])
            entry = f"goal {gid}"
            ids = self.check_req_list(f, entry, g.get("requirements", []))
            ann = self.goals.get((model_path, gid)) if model_path else None
            if ann is None:
                cands = [v for (m, k), v in self.goals.items() if k == gid]
                ann = cands[0] if len(cands) == 1 and not model_path else None
            if ann is None:
                self.error(f, entry, "no @goal annotation in models/ (stale coverage?)")
                ann = self.goals[(model_path, gid)] = {
                    "goal": gid, "model": model_path, "requirements": ids,
                    "label": g.get("label", ""), "line": 0}
            elif sorted(ids) != sorted(ann["requirements"]):
                self.error(f, entry, f"requirements {sorted(ids)} differ from the @goal "
                                     f"annotation {sorted(ann['requirements'])}")
            ann["covered"] = True
            reqs = sorted(set(ids) | set(ann["requirements"]))
            status = g.get("status")
            vec = g.get("vector")
            vec_list = g.get("vectors")
            if not isinstance(vec_list, list):
                vec_list = [vec] if isinstance(vec, str) else []
            vec = vec_list[0] if vec_list else None
            jid = g.get("justification")
            if status == "reached":
                reached += 1
                if not vec_list or not all(isinstance(v, str) for v in vec_list):
                    self.error(f, entry, "reached goal names no vector", reqs)
                for v in vec_list:
                    if isinstance(v, str) and v not in self.vectors:
                        self.error(f, entry, f"dangling reference: vector {v} not in "
                                             "vectors/*.jsonl", reqs)
            elif status == "unreachable":
                if not isinstance(jid, str) or not jid:
                    self.error(f, entry, "unreachable goal without a justification "
                                         "(spec/justifications/*.yaml)", reqs)
                elif jid not in just:
                    self.error(f, entry, f"dangling reference: justification {jid} not in "
                                         "spec/justifications/*.yaml", reqs)
                else:
                    j = just[jid]
                    if _goal_id(j.get("goal")) != gid:
                        self.error(f, entry, f"justification {jid} is for goal "
                                             f"{_goal_id(j.get('goal'))}, not {gid}", reqs)
                    elif model_path and j.get("model") != model_path:
                        self.error(f, entry, f"justification {jid} is for model "
                                             f"{j.get('model')}, not {model_path}", reqs)
                    else:
                        self.used_justifications.add(jid)
            else:
                self.error(f, entry, f"unknown status {status!r} (reached|unreachable)", reqs)
            ann.update({"status": status if isinstance(status, str) else "missing",
                        "vector": vec if isinstance(vec, str) else None,
                        "justification": jid if isinstance(jid, str) else None,
                        "requirements": reqs})
        if isinstance(data.get("reached"), int) and data["reached"] != reached:
            self.error(f, "reached", f"says {data['reached']} but {reached} goals are reached")
        if isinstance(data.get("labelled"), int) and data["labelled"] != len(data["goals"]):
            self.error(f, "labelled",
                       f"says {data['labelled']} but {len(data['goals'])} goals are listed")

    def _model_of_vectors(self, cov):
        jsonl = cov.with_name(cov.name[: -len(".coverage.json")] + ".jsonl")
        lines = self.read_lines(jsonl) if jsonl.is_file() else None
        if lines:
            try:
                head = json.loads(lines[0])
                if isinstance(head, dict) and isinstance(head.get("model"), str):
                    return head["model"]
            except json.JSONDecodeError:
                pass
        return None

    # -------------------------------------------------------------------- C++ ----
    def scan_cpp(self):
        root = self.src / "cpp"
        if not root.is_dir():
            return
        for f in sorted(p for p in root.rglob("*") if p.suffix in CPP_SUFFIXES and p.is_file()):
            rel = self.rel(f)
            is_test = bool(_TEST_PATH.match(rel))
            code = _CODE_PATH.match(rel)
            link = None if code is None else ("code" if code.group(1) == "runtime" else "tool")
            lines = self.read_lines(f)
            if lines is None:
                continue
            for n, line, m in _tagged(lines, _CPP_TAG):
                tag = m.group(1)
                entry = f"@{tag} (line {n})"
                ids, _rest, seen = self.parse_ids(f, entry, m.group(2))
                if not seen:
                    self.error(f, entry, "tag names no requirement")
                    continue
                if tag == "verifies":
                    if not is_test:
                        self.warn(f, entry, "@verifies outside a tests, conformance or fuzz folder "
                                            "is not a test link")
                        continue
                    test = self._test_after(lines, n)
                    if test is None and any("LLVMFuzzerTestOneInput" in ln
                                            for ln in self._code_lines_after(lines, n)[:1]):
                        # a libFuzzer target (run by ctest for a bounded time) is a test
                        test = f"fuzz:{Path(rel).stem}"
                    if test is None:
                        self.warn(f, entry, "@verifies is not directly above a TEST(...)")
                        test = self._unit_after(line, lines, n) or f"(line {n})"
                    elif ".DISABLED_" in test or test.startswith("DISABLED_"):
                        self.warn(f, entry, f"test {test} is disabled; not counted")
                        continue
                    for r in ids:
                        self.add(r, "unit", {"file": rel, "test": test})
                    self.test_set.add((rel, test))
                else:
                    if link is None:
                        self.warn(f, entry, "@implements outside cpp/runtime/<module>/{include,src} "
                                            "and cpp/offline/<module>/{include,src,tools} is not "
                                            "a code link")
                        continue
                    unit = self._unit_after(line, lines, n) or f"(line {n})"
                    for r in ids:
                        self.add(r, link, {"file": rel, "unit": unit})
                    self.unit_set.add((rel, unit))

    @staticmethod
    def _code_lines_after(lines, n, limit=12):
        """Code lines after line n (1-based), skipping comments, blanks and attributes."""
        in_block = False
        out = []
        for line in lines[n:n + limit]:
            s = line.strip()
            if in_block:
                if "*/" in s:
                    in_block = False
                    s = s.split("*/", 1)[1].strip()
                else:
                    continue
            if s.startswith("/*"):
                if "*/" not in s:
                    in_block = True
                    continue
                s = s.split("*/", 1)[1].strip()
            if not s or s.startswith("//") or s.startswith("*") or s.startswith("#"):
                continue
            out.append(s)
            if len(out) == 2:
                break
        return out

    def _test_after(self, lines, n):
        code = self._code_lines_after(lines, n)
        if not code:
            return None
        m = _TEST_MACRO.match(" ".join(code))
        return f"{m.group(2)}.{m.group(3)}" if m else None

    def _unit_after(self, tag_line, lines, n):
        before = tag_line.split("//", 1)[0].strip()
        candidates = [before] if before else []
        candidates += self._code_lines_after(lines, n)
        for s in candidates:
            s = re.sub(r"\[\[[^\]]*\]\]", "", s)
            s = re.sub(r"^template\s*<[^>]*>\s*", "", s)
            m = _CLASS.match(s)
            if m:
                return m.group(1)
            eq, par = s.find("="), s.find("(")
            if eq > 0 and (par < 0 or eq < par):
                vm = re.search(r"([A-Za-z_]\w*)\s*(?:\[[^\]]*\])?\s*$", s[:eq])
                if vm:
                    return vm.group(1)
            for fm in _FUNC.finditer(s):
                name = fm.group(1)
                if name.split("::")[-1] not in _NOT_A_UNIT:
                    return name
            if s.startswith("template"):
                continue
            if s.startswith("namespace"):
                return None
        return None

    # ----------------------------------------------------------------- proofs ----
    # An obligation's expected verdict: a "; @expect sat|unsat" comment after its tag.
    _PROOF_EXPECT = re.compile(r"^\s*;+\s*@expect\s+(\S+)\s*$")
    _PROOF_SOLVERS = ("z3", "cvc5")

    def scan_proofs(self):
        """Proof links from the tags in proofs/; then, if RESULTS_DIR/proofs/*.json exist
        (written by ``railproof_testgen proofs``), every tagged obligation must have a
        replay result in which both solvers returned its expected verdict."""
        root = self.src / "proofs"
        self.proof_obligations = {}  # name -> {"file", "line", "expect", "requirements"}
        if not root.is_dir():
            return
        for f in sorted(p for p in root.rglob("*") if p.is_file()):
            lines = self.read_lines(f)
            if lines is None:
                continue
            rel = self.rel(f)
            current = None
            for n, line in enumerate(lines, 1):
                m = _PROOF_TAG.search(line)
                if not m:
                    em = self._PROOF_EXPECT.match(line)
                    if em and current is not None and current["expect"] is None:
                        current["expect"] = em.group(1)
                    continue
                tag, body = m.group(1), m.group(2).strip()
                entry = f"@{tag} (line {n})"
                name = None
                current = None
                if tag == "obligation":
                    head = body.partition(" : ")[0].split(None, 1)
                    if head and not head[0].startswith("REQ-"):
                        name = head[0]
                        body = head[1] if len(head) > 1 else ""
                        entry = f"@obligation {name} (line {n})"
                ids, _rest, seen = self.parse_ids(f, entry, body.partition(" : ")[0])
                if not seen:
                    self.error(f, entry, "tag names no requirement")
                    continue
                for r in ids:
                    self.add(r, "proof", {"file": rel, "obligation": name or f.stem})
                self.obligation_set.add((rel, name or f.stem))
                if name is not None:
                    if name in self.proof_obligations:
                        first = self.proof_obligations[name]
                        if first["file"] != rel or first["line"] != n:
                            self.error(f, entry, f"obligation already tagged in "
                                                 f"{first['file']} (line {first['line']})", ids)
                        continue
                    current = {"file": rel, "line": n, "expect": None, "requirements": ids}
                    self.proof_obligations[name] = current
        self.scan_proof_results()

    def scan_proof_results(self):
        _d, files = self.result_files("proofs")
        if not files:
            return  # proof links come from the tags alone until the proofs have been replayed
        rows_by_name = {}
        for f in files:
            data = self.load_object(f, "obligations")
            if data is None:
                continue
            ids = self.check_req_list(f, "requirements", data.get("requirements"))
            if data.get("verdict") != "pass":
                self.error(f, "verdict", f"proof replay failed ({data.get('verdict')!r})", ids)
            for i, row in enumerate(data["obligations"]):
                if not isinstance(row, dict) or not isinstance(row.get("obligation"), str):
                    self.error(f, f"obligations[{i}]", "row needs an 'obligation' name")
                    continue
                rows_by_name.setdefault(row["obligation"], []).append((f, i, row))
        for name, ob in sorted(self.proof_obligations.items()):
            src_entry = f"@obligation {name} (line {ob['line']})"
            rows = rows_by_name.get(name)
            if not rows:
                self.error(ob["file"], src_entry, f"no replay result in "
                           f"{self.results.name}/proofs/*.json", ob["requirements"])
                continue
            exp = ob["expect"]
            if exp not in ("sat", "unsat"):
                self.error(ob["file"], src_entry, "no '@expect sat' or '@expect unsat' "
                           "after the tag", ob["requirements"])
                continue
            for f, i, row in rows:
                entry = str(row.get("name") or f"obligations[{i}]")
                if row.get("source") not in (None, ob["file"]):
                    self.error(f, entry, f"result is for {row.get('source')}, the obligation "
                               f"is tagged in {ob['file']}", ob["requirements"])
                if row.get("expected") != exp:
                    self.error(f, entry, f"expected verdict {row.get('expected')!r} differs "
                               f"from the source's @expect {exp}", ob["requirements"])
                for solver in self._PROOF_SOLVERS:
                    res = row.get(solver)
                    got = res.get("verdict") if isinstance(res, dict) else None
                    if got != exp:
                        self.error(f, entry, f"{solver} verdict {got!r}, expected {exp}",
                                   ob["requirements"])
                if row.get("meets_target") is not True:
                    self.error(f, entry, "target not met (meets_target is not true)",
                               ob["requirements"])
        for name in sorted(set(rows_by_name) - set(self.proof_obligations)):
            for f, i, row in rows_by_name[name]:
                self.error(f, str(row.get("name") or f"obligations[{i}]"),
                           f"stale result: no @obligation {name} in proofs/")

    # --------------------------------------------------------------- analysis ----
    def scan_analysis(self):
        d, files = self.result_files("analysis")
        if not files:
            if self._needs("analysis"):
                self.missing_result(d, "analysis", "no analysis results (analysis/*.json)")
            return
        for f in files:
            data = self.load_json(f)
            if data is None:
                continue
            if not isinstance(data, dict) or "requirements" not in data:
                self.warn(f, "-", "no top-level 'requirements' list; not linked")
                continue
            ids = self.check_req_list(f, "requirements", data["requirements"])
            verdict = data.get("verdict", data.get("status"))
            if (isinstance(verdict, str) and verdict.lower() in FAILED_VERDICTS) \
                    or data.get("passed") is False or data.get("meets_target") is False:
                self.error(f, "verdict", f"analysis result failed ({verdict!r})", ids)
            # tables of cases: a row that misses its target fails the analysis
            for key_, rows in sorted(data.items()):
                if isinstance(rows, list):
                    for i, row in enumerate(rows):
                        if isinstance(row, dict) and row.get("meets_target") is False:
                            self.error(f, f"{key_}[{i}]", "target not met "
                                       "(meets_target is false)", ids)
            self.counts["analysis_results"] += 1
            for r in ids:
                self.add(r, "analysis", self.rel(f))

    # ------------------------------------------------------------------ rules ----
    def model_links(self):
        """Model and goal links from annotations and results together: an annotated
        property without a result appears with verdict "missing"."""
        for name, p in self.properties.items():
            results = p["results"] or [{"model": p["files"][0], "verdict": "missing"}]
            for res in results:
                for r in p["requirements"]:
                    if r in self.links:
                        self.add(r, "model", {"property": name, "verdict": res["verdict"],
                                              "model": res["model"]})
        for g in self.goals.values():
            for r in g["requirements"]:
                if r in self.links:
                    self.add(r, "goals", g["goal"])

    def _needs(self, method):
        return any(method in (r.get("verification") or [])
                   for r in self.model["requirements"].values())

    def check_requirements(self):
        for rid, r in sorted(self.model["requirements"].items()):
            f, L = r["file"], self.links[rid]
            ver = r.get("verification") or []
            for method in ver:
                kind = METHOD_LINK.get(method)
                if kind is None:
                    continue
                if kind == "model":
                    if not any(p["verdict"] == "verified" for p in L["model"]):
                        annotated = any(rid in p["requirements"]
                                        for p in self.properties.values())
                        if not annotated:
                            self.error(self.rel_spec(f), rid, "verification 'model': no "
                                       "@property in models/ names this requirement", [rid])
                        elif "model" in self.missing:
                            self.warn(self.rel_spec(f), rid, "verification 'model': not yet "
                                      "verified (model-checking results missing)")
                        else:
                            self.error(self.rel_spec(f), rid, "verification 'model': no "
                                       "property naming it is verified", [rid])
                    continue
                if not L[kind]:
                    if kind in RESULT_KINDS and kind in self.missing:
                        self.warn(self.rel_spec(f), rid, f"verification '{method}': no link "
                                  f"yet ({RESULT_KINDS[kind]} results missing)")
                    else:
                        what = {"vectors": "no vector names it",
                                "unit": "no @verifies test in cpp/tests names it",
                                "analysis": "no analysis result names it",
                                "proof": "no proof obligation names it"}[kind]
                        self.error(self.rel_spec(f), rid, f"verification '{method}': {what}",
                                   [rid])
            if r.get("implemented_by", "runtime") == "offline":
                if not L["tool"]:
                    self.error(self.rel_spec(f), rid, "implemented_by offline: no @implements unit "
                               "under cpp/offline names it", [rid])
            elif r.get("sil") == 4 and set(ver) != {"analysis"} and not L["code"]:
                extra = (f" (offline code never implements a runtime requirement: "
                         f"{', '.join(sorted({u['file'] for u in L['tool']}))})" if L["tool"] else "")
                self.error(self.rel_spec(f), rid, "SIL-4 runtime requirement has no @implements "
                           "unit under cpp/runtime" + extra, [rid])

    def rel_spec(self, f):
        return self.rel(Path(f))

    def check_justifications(self):
        for jid, j in sorted(self.model["justifications"].items()):
            if not (self.src / str(j.get("model"))).is_file():
                self.error(self.rel_spec(j["file"]), jid,
                           f"dangling reference: model {j.get('model')} not found")
            if "vectors" not in self.missing and jid not in self.used_justifications:
                self.warn(self.rel_spec(j["file"]), jid,
                          "justification is not used by any unreachable goal")

    # ------------------------------------------------------------------- main ----
    def run(self):
        model, spec_report = check_spec(self.spec_dir)
        if spec_report.errors:
            self.report = spec_report
            return None
        for w in spec_report.warnings:
            self.warn(Path(w.file), w.entry, w.reason)
        self.model = model
        # every requirement belongs to the capability of its area (spec/capabilities.yaml)
        try:
            reg = registry_mod.load(self.spec_dir)
        except SpecError as exc:
            self.error(Path(exc.file), exc.entry, exc.reason)
            return None
        self.capability = {}
        for rid, r in sorted(model["requirements"].items()):
            cap = reg.of_area(r["area"])
            if cap is None:
                self.error(self.rel_spec(r["file"]), rid, f"area {r['area']} belongs to no capability of "
                                                          f"{self.rel(reg.file)}")
            self.capability[rid] = cap.name if cap else None
        self.links = {rid: {k: [] for k in LINK_KINDS} for rid in model["requirements"]}
        self.problems = {rid: [] for rid in model["requirements"]}
        self.scan_models()
        self.scan_spin()
        self.scan_vectors()
        self.scan_cpp()
        self.scan_proofs()
        self.scan_analysis()
        self.model_links()
        self.check_requirements()
        self.check_justifications()
        return self.render()

    def render(self):
        def key(x):
            if isinstance(x, dict):
                return json.dumps(x, sort_keys=True)
            m = re.match(r"^G(\d+)$", str(x))  # goals in numeric order
            return f"G{int(m.group(1)):09d}" if m else str(x)

        reqs = []
        covered = {k: 0 for k in LINK_KINDS}
        by_sil = {}
        for rid, r in sorted(self.model["requirements"].items()):
            links = {k: sorted(v, key=key) for k, v in self.links[rid].items()}
            for k, v in links.items():
                covered[k] += bool(v)
            by_sil[str(r.get("sil"))] = by_sil.get(str(r.get("sil")), 0) + 1
            problems = sorted(self.problems[rid])
            reqs.append({
                "id": rid, "area": r["area"], "capability": self.capability.get(rid),
                "title": r.get("title"), "sil": r.get("sil"),
                "source": list(r.get("source") or []), "hazards": sorted(r.get("hazards") or []),
                "verification": list(r.get("verification") or []),
                "implemented_by": r.get("implemented_by", "runtime"), "links": links,
                "status": "error" if problems else "ok", "problems": problems})
        props = [res["verdict"] for p in self.properties.values() for res in p["results"]]
        prop_missing = sum(1 for p in self.properties.values() if not p["results"])
        goals = list(self.goals.values())
        summary = {
            "requirements": len(reqs),
            "ok": sum(r["status"] == "ok" for r in reqs),
            "error": sum(r["status"] == "error" for r in reqs),
            "sil4": by_sil.get("4", 0),
            "by_sil": dict(sorted(by_sil.items())),
            "with_link": covered,
            "properties": {v: props.count(v) for v in ("verified", "violated", "incomplete")}
            | {"missing": prop_missing},
            "mutants": {v: sum(m["verdict"] == v for m in self.mutants.values())
                        for v in ("rejected", "survived", "missing")},
            "goals": {"labelled": len(goals),
                      "reached": sum(g["status"] == "reached" for g in goals),
                      "unreachable": sum(g["status"] == "unreachable" for g in goals),
                      "missing": sum(g["status"] == "missing" for g in goals)},
            "errors": len(self.report.errors),
            "warnings": len(self.report.warnings),
            "unit_tests": len(self.test_set),
            "code_units": len(self.unit_set),
            "proof_obligations": len(self.obligation_set),
        } | self.counts
        goal_list = sorted(({k: g[k] for k in ("goal", "model", "label", "requirements",
                                                "status", "vector", "justification")}
                            for g in goals), key=lambda g: (str(g["model"]), key(g["goal"])))
        return {"schema": SCHEMA, "requirements": reqs, "goals": goal_list,
                "errors": sorted(str(e) for e in self.report.errors),
                "warnings": sorted(str(w) for w in self.report.warnings),
                "summary": dict(sorted(summary.items()))}



def build_trace(spec_dir, src, results, allow_missing=False):
    """Return (trace dict or None if the spec itself is invalid, Report)."""
    t = Tracer(spec_dir, src, results, allow_missing)
    data = t.run()
    return data, t.report


def write_json(path, data):
    write_atomic(path, json.dumps(data, indent=2, sort_keys=True, ensure_ascii=False) + "\n",
                 if_changed=False)


def run(args):
    if not Path(args.src).is_dir():
        raise SpecError(args.src, "-", "source tree not found")
    data, report = build_trace(args.spec, args.src, args.results, args.allow_missing_results)
    report.print()
    if data is None:
        print(f"trace: specification invalid ({len(report.errors)} error(s)); "
              "no trace written", file=sys.stderr)
        return 1
    write_json(args.out, data)
    s = data["summary"]
    msg = (f"trace: {s['requirements']} requirements ({s['ok']} ok, "
           f"{s['error']} with problems), {s['errors']} error(s), "
           f"{s['warnings']} warning(s) -> {args.out}")
    if report.errors:
        print(msg, file=sys.stderr)
        return 1
    print(msg)
    return 0


def register(sub):
    add_command(sub, "trace", run, "check requirement traceability and write trace.json",
                """Link every requirement to model properties, vectors, code, tests, proofs and
                analysis results; fail on dangling references, violated properties, surviving
                mutants, unjustified unreachable goals and unverified requirements.""",
                spec=SPEC_DIR, src="repository root (models/, cpp/, proofs/)",
                results="results directory (spin/, vectors/, analysis/)", out="trace.json to write",
                allow_missing_results={"action": "store_true",
                                       "help": "missing results directories are warnings (before "
                                               "the pipeline ran)"})
