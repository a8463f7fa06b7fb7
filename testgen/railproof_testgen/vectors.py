"""Derive conformance vectors from a SPIN model: the generic engine.

``railproof_testgen vectors --model models/<m>.pml --params DIR --spec spec --work DIR --out DIR``

Every model's vectors are made the same way (conventions §1, the design notes spec/design/<cap>.md);
what differs lives in the capability's part, testgen/railproof_testgen/capabilities/<cap>.py,
found through the capability registry (spec/capabilities.yaml): its configuration table, the
parser of the model's @IN/@OUT output, the conversion to the vector step format, the
requirements a run shows, the header, the vector ids and any rule of its own (class Part).

- Trap vectors. Every `// @goal K` is a trap property "goal flag g[K] is never set", searched in
  the configuration its annotation names (`[config X]`, -DX; none: the model's default
  configuration). The goals of one configuration are searched together, by one breadth-first
  search that keeps each goal's first violation (spin.search_goals: the same shortest run as
  the goal's own trap property); the run, replayed with `spin -t`, is the goal's vector. A
  goal whose label contains one of the part's boundary words gives a boundary vector.
- Variants. The goals of the default configuration are searched again in each `// @variant`
  of the model: all of them (Part.variant_search = "all") or those the default configuration
  cannot reach ("unreachable"); a goal reached there gives a vector in the variant's file.
- Random walks: seeded simulations (`spin -n<seed>`) in the configurations the part's table
  gives walks to; the seed is in the id.
- Goal coverage (<model>.coverage.json): every goal reached with its vectors, or unreachable
  (the search is complete) with the justification spec/justifications/<cap>.yaml gives it
  (states searched recorded). An unreachable goal without one, or a justification of a goal
  that is reached or unknown, fails the command (after the files are written, so that the
  coverage shows the problem).
- Files: one JSON Lines file per file suffix of the configuration table, <model><suffix>.jsonl
  (a header, then the vectors), each line checked against spec/schemas/vectors_<cap>.schema.json
  before anything is written; every file written atomically; files of configurations no
  longer generated are removed.
- Whole or rejected: the header states the number of vector lines (vector_count) and the
  SHA-256 of the text after the header line, the vector lines exactly as written, each with
  its newline (vectors_sha256); a file cut at a line boundary, a line dropped, duplicated or
  edited no longer matches its header (check_seal; the conformance runners check the same,
  cpp/testing/include/railproof/testing/vector_file.hpp). The header format
  (spec/schemas/vector_header.schema.json) has the version SCHEMA_VERSION.
"""
from __future__ import annotations

import hashlib
import importlib
import json
from abc import ABC, abstractmethod
import os
import re
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import jsonschema
import referencing

from . import __version__, add_command
from . import registry as registry_mod
from . import spin as spin_mod
from .errors import PipelineError, SpecError
from .files import write_atomic
from .spec import load_yaml

REACHED, UNREACHABLE = "reached", "unreachable"
KINDS = ("trap", "boundary", "random")
SCHEMA_VERSION = 2  # of the vector files (header "schema_version"): the one the runners read
HEADER_SCHEMA = "vector_header.schema.json"  # the header fields every vector file has


def _progress(msg):
    print(f"vectors: {msg}", flush=True)


# ---- what a capability contributes ------------------------------------------------------------
@dataclass(frozen=True)
class Configuration:
    """A configuration of the model in which vectors are generated.

    define: its -D symbol (None: the model's default configuration).
    suffix: its vectors go to <model><suffix>.jsonl ("" the model's main file); configurations
            that share a suffix share the file, whose header is that of the first of them in
            the table.
    tag:    put in its vector ids (Part.vector_id).
    walks:  random walks in it: 0 none, 1 the --walks count, k > 1 that count // k (at least one).
    walk_evidence: its walks also evidence the requirements of the properties verified in it."""
    define: str | None
    suffix: str = ""
    tag: str = ""
    walks: int = 0
    walk_evidence: bool = False

    @property
    def name(self) -> str:
        return self.define or "default"

    def walk_count(self, walks: int) -> int:
        """The number of random walks in this configuration for --walks `walks`."""
        if self.walks <= 0:
            return 0
        return walks if self.walks == 1 else max(1, walks // self.walks)


class Part(ABC):
    """A capability's part of vector generation: capabilities/<cap>.py defines PART, an instance
    of a subclass that sets prefix and configurations and implements the abstract methods
    (bounds, parse_events, to_steps, observed_requirements, header); the other members have
    the common default.
    A configuration is named by its define (None: the model's default configuration)."""
    prefix: str = ""                  # vector ids begin <prefix>-<KIND>-
    configurations: tuple = ()        # Configuration, the model's default one first
    boundary_words = ("boundary",)    # a goal label containing one gives a boundary vector
    variant_search = "all"            # default-configuration goals searched in each @variant
    walk_defines = ("WALK",)          # -D symbols of a random walk
    walk_steps = None                 # a walk's length in SPIN statements (spin -u), if the model
    #                                   does not end it itself
    walk_events = None                # the model bound giving a walk's number of events (None: any, >= 1)

    def configuration(self, define) -> Configuration:
        for c in self.configurations:
            if c.define == define:
                return c
        raise KeyError(define)

    # what the capability implements
    @abstractmethod
    def bounds(self, model: Path, params_pml: Path) -> dict:
        """The model bounds the part needs (model_bounds of the generated <model>_params.pml)."""

    @abstractmethod
    def parse_events(self, text: str) -> list:
        """The events of a replay or walk (spin's output: the model's @IN/@OUT lines)."""

    @abstractmethod
    def to_steps(self, events: list, bounds: dict, define) -> list:
        """The events as the steps of a vector (the capability's schema)."""

    @abstractmethod
    def observed_requirements(self, steps: list) -> set:
        """The requirements a run shows (added to a goal's own)."""

    @abstractmethod
    def header(self, target: "Target", define) -> dict:
        """The header line of the file of a configuration (Target.header and the part's fields)."""

    # the common rules, overridden where a capability has its own
    def walk_length(self, bounds: dict, define) -> int | None:
        """The number of events a random walk must give (None: at least one)."""
        return bounds[self.walk_events] if self.walk_events else None

    def vector_id(self, kind: str, define, tail: str) -> str:
        """tail: the goal (G<k>) or the seed (S<seed>)."""
        return f"{self.prefix}-{kind.upper()}-{self.configuration(define).tag}{tail}"

    def vectors(self, target: "Target", define, events, vid: str, kind: str, goal: str | None,
                seed: int | None, requirements) -> list:
        """The vectors of one run of the model: one, with the requirements it shows."""
        steps = self.to_steps(events, target.bounds, define)
        return [{"id": vid, "requirements": sorted(set(requirements) | self.observed_requirements(steps)),
                 "goal": goal, "kind": kind, "seed": seed, "steps": steps}]

    def order(self, define, vectors: list) -> list:
        """The order of a file's vectors (define: the file's configuration): boundary, trap, then
        random vectors, each by goal or seed number."""
        return sorted(vectors, key=lambda v: (v["kind"] == "random", v["kind"] == "trap", id_order(v["id"])))


def model_lines(text: str, patterns: dict):
    """(kind, match, line) of every @IN and @OUT line of a replay or walk (spin's output), kind
    naming the first of patterns ({kind: regular expression}) that matches it; a line that none
    matches is an error."""
    for line in text.splitlines():
        if "@IN" not in line and "@OUT" not in line:
            continue
        for kind, rx in patterns.items():
            if m := rx.search(line):
                yield kind, m, line
                break
        else:
            raise PipelineError(f"unrecognised model output line: {line.strip()}")


def id_order(vid: str):
    """Sort key of an id by its last number (G<k>, S<seed>), numerically."""
    m = re.search(r"(\d+)$", vid)
    return (vid[: m.start()] if m else vid, int(m.group(1)) if m else 0)


def model_bounds(params_pml: Path, required=()) -> dict:
    """The model bounds of a generated <model>_params.pml (MODEL_<NAME> -> name, a "model_"
    prefix of the name dropped); a required one missing is an error naming it."""
    raw = spin_mod.read_bounds(params_pml)
    b = {k[len("model_"):] if k.startswith("model_") else k: v for k, v in raw.items()}
    area = Path(params_pml).stem.removesuffix("_params")
    for key in required:
        if key not in b:
            raise SpecError(params_pml, f"MODEL_{key.upper()}",
                            f"model bound missing (spec/parameters/{area}.yaml model_bounds)")
    return b


@dataclass
class Target:
    """The model the vectors are generated from, as the parts see it."""
    path: Path
    annotations: spin_mod.Annotations
    bounds: dict
    spin_version: str

    @property
    def rel(self) -> str:
        return f"models/{self.path.name}"

    @cached_property
    def sha256(self) -> str:
        return spin_mod.sha256_file(self.path)

    def header(self, **fields) -> dict:
        """A vector file's header: the fields every header has, then the part's."""
        return {"kind": "header", "schema_version": SCHEMA_VERSION, "model": self.rel, "model_sha256": self.sha256,
                "generator": f"railproof_testgen {__version__}", "spin_version": self.spin_version, **fields}

    def property_requirements(self, define) -> set:
        return {r for p in self.annotations.properties if define in p.configs for r in p.requirements}


def capability_part(spec_dir: Path, model: Path):
    """(capability name, part) of the capability the registry lists the model under: the PART of
    capabilities/<name>.py, or its PARTS[<model name>] where a capability has several models."""
    reg = registry_mod.load(spec_dir)
    cap = reg.of_model(model)
    if cap is None:
        raise SpecError(reg.file, Path(model).stem, f"no capability lists the model {Path(model).name}")
    try:
        mod = importlib.import_module(f"{__package__}.capabilities.{cap.name}")
    except ModuleNotFoundError as exc:
        if exc.name != f"{__package__}.capabilities.{cap.name}":
            raise
        raise SpecError(cap.vector_part, cap.name, "missing: the capability's part of vector generation") from None
    # one part for the capability (PART), or one per model of the capability (PARTS, by name)
    parts = getattr(mod, "PARTS", None)
    if parts is not None:
        part = parts.get(Path(model).stem)
        if part is None:
            raise SpecError(cap.vector_part, "PARTS", f"no part for the model {Path(model).stem}")
    else:
        part = getattr(mod, "PART", None)
    if not isinstance(part, Part):
        raise SpecError(cap.vector_part, "PART", "must be an instance of railproof_testgen.vectors.Part")
    return cap.name, part


def load_justifications(spec_dir: Path, capability: str, model_rel: str) -> dict:
    """{goal: justification id} of spec/justifications/<capability>.yaml for the model."""
    f = Path(spec_dir) / "justifications" / f"{capability}.yaml"
    if not f.is_file():
        return {}
    out = {}
    for i, e in enumerate(load_yaml(f).get("justifications") or []):
        if not isinstance(e, dict) or not all(isinstance(e.get(k), str) for k in ("id", "goal", "model")):
            raise SpecError(f, f"justifications[{i}]", "an entry needs 'id', 'goal' and 'model'")
        if e["model"] != model_rel:
            continue
        if e["goal"] in out:
            raise SpecError(f, e["id"], f"goal {e['goal']} is already justified by {out[e['goal']]}")
        out[e["goal"]] = e["id"]
    return out


# ---- files ------------------------------------------------------------------------------------
def _most_specific(err):
    """Under a oneOf/anyOf failure, the deepest error of the alternative that fails least (the
    one the line was meant to be), so that a message names the field that is wrong (e.g.
    steps/0/onboard/in/reports/0: 'requesters' is a required property) instead of quoting the
    whole line or blaming another alternative."""
    while err is not None and err.context:
        alternatives = {}
        for e in err.context:
            alternatives.setdefault(e.relative_schema_path[0], []).append(e)
        err = max(min(alternatives.values(), key=len), key=lambda e: len(e.absolute_path))
    return err


def schema_validator(schema_path: Path):
    """The validator of a capability's vector schema; its header refers to the shared header
    definition (HEADER_SCHEMA beside it, by its $id), where there is one."""
    schema_path = Path(schema_path)
    registry = referencing.Registry()
    if (shared_path := schema_path.parent / HEADER_SCHEMA).is_file():
        shared = json.loads(shared_path.read_text(encoding="utf-8"))
        registry = registry.with_resource(shared["$id"], referencing.Resource.from_contents(shared))
    return jsonschema.Draft202012Validator(json.loads(schema_path.read_text(encoding="utf-8")), registry=registry)


def dump_line(obj) -> str:
    """One JSON Lines line as the vector files have it (keys sorted, no spaces, newline)."""
    return json.dumps(obj, sort_keys=True, separators=(",", ":")) + "\n"


def seal(header: dict, body: str) -> dict:
    """The header with the count and the digest of body, the vector lines as written (each
    with its newline): vector_count, vectors_sha256."""
    return {**header, "vector_count": body.count("\n"),
            "vectors_sha256": hashlib.sha256(body.encode("utf-8")).hexdigest()}


def sealed_jsonl(schema_path: Path, header: dict, vectors: list, name: str) -> str:
    """The text of a vector file: the header, sealed (seal), then one vector per line; every
    line validated against the JSON schema of the vector format first (a violation is a
    PipelineError naming the file, line and field)."""
    body = "".join(map(dump_line, vectors))
    lines = [seal(header, body), *vectors]
    validator = schema_validator(schema_path)
    for n, obj in enumerate(lines, 1):
        # the most relevant top-level error (best_match would descend into a oneOf itself and
        # may blame the vector alternative for a header's fault)
        err = _most_specific(max(validator.iter_errors(obj), key=jsonschema.exceptions.relevance, default=None))
        if err:
            message = err.message if len(err.message) <= 300 else err.message[:300] + " ..."
            raise PipelineError(f"generated {name} line {n} violates the vector schema: "
                                f"{'/'.join(map(str, err.absolute_path)) or '(top level)'}: {message}")
    return dump_line(lines[0]) + body


def check_seal(text: str, name: str) -> dict:
    """The header of a vector file's text if the file is whole: its first line a header of
    schema version SCHEMA_VERSION whose vector_count and vectors_sha256 match the lines after
    it; else a PipelineError "<name>:<line>: <reason>"."""
    head, newline, body = text.partition("\n")
    try:
        header = json.loads(head) if newline else None
    except json.JSONDecodeError as exc:
        raise PipelineError(f"{name}:1: malformed JSON: {exc.msg}") from None
    if not isinstance(header, dict) or header.get("kind") != "header":
        raise PipelineError(f"{name}:1: first line is not a vector header (\"kind\":\"header\")")
    if header.get("schema_version") != SCHEMA_VERSION:
        raise PipelineError(f"{name}:1: schema_version {header.get('schema_version')} is not "
                            f"supported (expected {SCHEMA_VERSION})")
    if body and not body.endswith("\n"):
        raise PipelineError(f"{name}:{body.count(chr(10)) + 2}: the last line has no line end (file cut short?)")
    sealed = seal({}, body)
    if header.get("vector_count") != sealed["vector_count"]:
        raise PipelineError(f"{name}:1: the header states {header.get('vector_count')} vectors, "
                            f"the file has {sealed['vector_count']}")
    if header.get("vectors_sha256") != sealed["vectors_sha256"]:
        raise PipelineError(f"{name}:1: the vector lines do not match the header's vectors_sha256 "
                            "(a vector was changed)")
    return header


# ---- the engine -------------------------------------------------------------------------------
@dataclass
class Outcome:
    """A goal's search in one configuration."""
    status: str                 # REACHED or UNREACHABLE
    events: list | None         # the parsed replay of its trail (reached)
    states: int | None          # states of the complete search (unreachable)


class Generation:
    """One run of the vectors command for one model and its capability's part."""

    def __init__(self, capability: str, part: Part, model: Path, params_dir: Path, spec_dir: Path,
                 workdir: Path, out_dir: Path, walks: int, walk_steps: int | None, jobs: int):
        self.capability, self.part = capability, part
        self.model, self.params_dir, self.spec_dir = Path(model), Path(params_dir), Path(spec_dir)
        self.workdir, self.out_dir = Path(workdir), Path(out_dir)
        self.walks, self.jobs = walks, max(1, jobs)
        self.walk_steps = walk_steps if walk_steps is not None else part.walk_steps
        if walk_steps is not None and part.walk_steps is None:
            raise SpecError(self.model, "--walk-steps", f"the model ends its random walks itself (capability "
                                                        f"{capability}: no walk length in SPIN statements)")
        if part.variant_search not in ("all", "unreachable"):
            raise SpecError(f"capabilities/{capability}.py", "variant_search",
                            f"{part.variant_search!r} is neither 'all' nor 'unreachable'")
        ann = spin_mod.parse_annotations(self.model)
        if not ann.goals:
            raise SpecError(self.model, "-", "no // @goal annotations: nothing to generate")
        known = {c.define for c in part.configurations}
        for g in ann.goals:
            if g.config not in known:
                raise SpecError(self.model, g.gid, f"goal in configuration {g.config}, in which capability "
                                                   f"{capability} generates no vectors (capabilities/{capability}.py)")
        for v in ann.variants:
            if v.define not in known:
                raise SpecError(self.model, v.define, f"variant in which capability {capability} generates "
                                                      f"no vectors (capabilities/{capability}.py)")
        for define, _ in ann.walk_only:
            if define not in known or not part.configuration(define).walks:
                raise SpecError(self.model, define, f"walk-only configuration in which capability {capability} "
                                                    f"draws no random walks (capabilities/{capability}.py)")
        bounds = part.bounds(self.model, spin_mod.params_file(self.params_dir, self.model))
        self.target = Target(self.model, ann, bounds, spin_mod.spin_version())
        self.schema = self.spec_dir / "schemas" / f"vectors_{capability}.schema.json"
        self.justification_file = f"spec/justifications/{capability}.yaml"
        self.justifications = load_justifications(self.spec_dir, capability, self.target.rel)

    @property
    def ann(self):
        return self.target.annotations

    def pool(self):
        return ThreadPoolExecutor(max_workers=self.jobs)

    # ---- trap searches ----------------------------------------------------------------------
    def search(self, plan: dict) -> dict:
        """plan: {define: [goals]} -> {(goal number, define): Outcome}. One search per
        configuration, then the replay of every trail, in parallel."""
        plan = {d: gs for d, gs in plan.items() if gs}

        def run(define):
            name = self.part.configuration(define).name
            _progress(f"[{name}] compiling the trap model and searching {len(plan[define])} goal(s) at once")
            s = spin_mod.search_goals(self.model, self.params_dir, self.workdir / f"traps-{name}",
                                      ["TRAPS"] + ([define] if define else []), [g.number for g in plan[define]],
                                      self.ann.pan_flags)
            _progress(f"[{name}] {len(s.trails)} of {len(plan[define])} goal(s) reached "
                      f"({s.res['states_stored']} states, {s.res['time_s']} s)")
            return define, s

        with self.pool() as ex:
            searches = dict(ex.map(run, plan))
            trails = [(d, t) for d, s in searches.items() for t in sorted(set(s.trails.values()))]

            def replay(job):
                define, trail = job
                s = searches[define]
                return job, self.part.parse_events(s.replay(trail, s.dir / f"replay-{trail}"))

            replayed = dict(ex.map(replay, trails))
        out = {}
        for define, goals in plan.items():
            s = searches[define]
            for g in goals:
                if g.number not in s.trails:
                    out[(g.number, define)] = Outcome(UNREACHABLE, None, s.res["states_stored"])
                    continue
                events = replayed[(define, s.trails[g.number])]
                if not events:
                    raise PipelineError(f"{self.model.name}: goal {g.gid} [{self.part.configuration(define).name}]: "
                                        f"the replay of its trail produced no events")
                out[(g.number, define)] = Outcome(REACHED, events, None)
        return out

    def search_plan(self):
        """Every goal in its configuration, then in the variants (Part.variant_search)."""
        plan = {}
        for g in self.ann.goals:
            plan.setdefault(g.config, []).append(g)
        default_goals = plan.get(None, [])
        if self.part.variant_search == "all":
            for v in self.ann.variants:
                plan.setdefault(v.define, []).extend(default_goals)
        outcomes = self.search(plan)
        if self.part.variant_search == "unreachable":
            missing = [g for g in default_goals if outcomes[(g.number, None)].status == UNREACHABLE]
            if missing and self.ann.variants:
                _progress(f"variants {', '.join(v.define for v in self.ann.variants)}: searching "
                          f"{len(missing)} goal(s) unreachable in the default configuration")
                outcomes.update(self.search({v.define: missing for v in self.ann.variants}))
        return outcomes

    # ---- random walks ---------------------------------------------------------------------
    def walk(self, job):
        define, seed = job
        name = self.part.configuration(define).name
        # spin writes scratch files into its working directory: one directory per walk
        wd = spin_mod.stage(self.model, self.params_dir, self.workdir / f"walk{seed}-{name}")
        flags = [f"-D{d}" for d in (*self.part.walk_defines, *([define] if define else []))]
        flags += [f"-n{seed}"] + ([f"-u{self.walk_steps}"] if self.walk_steps else [])
        r = spin_mod._run(["spin", *flags, self.model.name], wd, timeout=300)
        if r.returncode != 0:
            raise PipelineError(f"{self.model.name}: random walk seed {seed} [{name}] failed: {r.stderr[-1000:]}")
        events = self.part.parse_events(r.stdout)
        want = self.part.walk_length(self.target.bounds, define)
        if (want is None and not events) or (want is not None and len(events) != want):
            raise PipelineError(f"{self.model.name}: random walk seed {seed} [{name}] produced {len(events)} "
                                f"event(s), expected {want if want is not None else 'at least one'}")
        return job, events

    # ---- the whole run --------------------------------------------------------------------
    def run(self) -> dict:
        self.workdir.mkdir(parents=True, exist_ok=True)
        per_config = {c.define: [] for c in self.part.configurations}  # the vectors of each configuration
        coverage, problems = self.goal_vectors(self.search_plan(), per_config)
        self.walk_vectors(per_config)
        return self.write(coverage, per_config, problems)

    def goal_vectors(self, outcomes: dict, per_config: dict):
        """The vectors of the reached goals and the coverage record of every goal; the problems
        of the justifications (an unreachable goal without one, one for a goal that is not)."""
        part, target = self.part, self.target
        coverage, problems = [], []

        def made(g, define, outcome):
            kind = "boundary" if any(w in g.label.lower() for w in part.boundary_words) else "trap"
            vecs = part.vectors(target, define, outcome.events, part.vector_id(kind, define, g.gid), kind,
                                g.gid, None, g.requirements)
            per_config[define].extend(vecs)
            return [v["id"] for v in vecs]

        for g in self.ann.goals:
            home = outcomes[(g.number, g.config)]
            where = part.configuration(g.config).name
            entry = {"id": g.gid, "label": g.label, "requirements": g.requirements, "status": home.status,
                     "configuration": where, "vectors": [], "justification": None, "states_searched": None}
            if home.status == REACHED:
                entry["vectors"] = made(g, g.config, home)
                _progress(f"{g.gid} [{where}] reached in {len(home.events)} step(s): {g.label}")
            else:
                entry["justification"] = self.justifications.get(g.gid)
                entry["states_searched"] = home.states
                _progress(f"{g.gid} [{where}] UNREACHABLE ({home.states} states searched): {g.label}")
                if not entry["justification"]:
                    problems.append(f"{self.justification_file}: {g.gid}: goal unreachable in {where} "
                                    f"({g.label}) and not justified (model {target.rel})")
            for v in self.ann.variants if g.config is None else []:
                found = outcomes.get((g.number, v.define))
                if found is not None and found.status == REACHED:
                    entry.setdefault("variant_vectors", []).extend(made(g, v.define, found))
                    entry["variant"] = v.define
                    _progress(f"{g.gid} reached in variant {v.define} in {len(found.events)} step(s)")
            coverage.append(entry)
        unreachable = {c["id"] for c in coverage if c["status"] == UNREACHABLE}
        for gid, jid in sorted(self.justifications.items()):
            if gid not in unreachable:
                what = "reached" if any(c["id"] == gid for c in coverage) else "not a goal of the model"
                problems.append(f"{self.justification_file}: {jid}: justifies goal {gid}, which is {what}")
        return coverage, problems

    def walk_vectors(self, per_config: dict):
        """The random walks of every configuration the part gives walks to."""
        part, target = self.part, self.target
        counts = {c.define: c.walk_count(self.walks) for c in part.configurations}
        jobs = [(define, seed) for define, n in counts.items() for seed in range(1, n + 1)]
        _progress(f"{len(jobs)} random walks (" + ", ".join(f"{n} in {part.configuration(d).name}"
                                                           for d, n in counts.items() if n) + ")")
        with self.pool() as ex:
            walked = list(ex.map(self.walk, jobs))
        for (define, seed), events in walked:
            extra = target.property_requirements(define) if part.configuration(define).walk_evidence else set()
            per_config[define].extend(part.vectors(target, define, events, part.vector_id("random", define, f"S{seed}"),
                                                   "random", None, seed, extra))

    def write(self, coverage, per_config, problems) -> dict:
        part, stem = self.part, self.model.stem
        files = {}  # file name -> (configuration of its header, vectors)
        for c in part.configurations:
            name = f"{stem}{c.suffix}.jsonl"
            files.setdefault(name, (c.define, []))[1].extend(per_config[c.define])
        texts = {}
        for name, (define, vecs) in files.items():
            if vecs or name == f"{stem}.jsonl":
                texts[name] = sealed_jsonl(self.schema, part.header(self.target, define), part.order(define, vecs),
                                           name)
        all_vecs = [v for _, vecs in files.values() for v in vecs]
        reached = sum(c["status"] == REACHED for c in coverage)
        cov = {"schema": "railproof/coverage/1", "model": self.target.rel, "goals": coverage, "reached": reached,
               "labelled": len(coverage),
               "unreachable_justified": sum(c["status"] == UNREACHABLE and bool(c["justification"]) for c in coverage),
               "vectors": {k: sum(v["kind"] == k for v in all_vecs) for k in KINDS},
               "files": {name: len(files[name][1]) for name in texts}}
        self.out_dir.mkdir(parents=True, exist_ok=True)
        for old in self.out_dir.glob(f"{stem}.*.jsonl"):
            if old.name not in texts:
                old.unlink()  # a file of a configuration no longer generated
        for name, text in texts.items():
            write_atomic(self.out_dir / name, text, if_changed=False)
        write_atomic(self.out_dir / f"{stem}.coverage.json", json.dumps(cov, indent=2, sort_keys=True) + "\n",
                     if_changed=False)
        _progress(f"goal coverage {reached}/{len(coverage)} reached, {cov['unreachable_justified']} unreachable "
                  f"justified; {len(all_vecs)} vectors written ("
                  + ", ".join(f"{n}: {k}" for n, k in cov["files"].items()) + ")")
        if problems:
            raise PipelineError(f"{self.model.name}: goal coverage: " + "; ".join(problems))
        return cov


def generate(model: Path, params_dir: Path, spec_dir: Path, workdir: Path, out_dir: Path, walks: int = 50,
             walk_steps: int | None = None, jobs: int = 2, part: tuple | None = None) -> dict:
    """Generate the vectors of a model; part: (capability name, Part) instead of the registry's."""
    capability, the_part = part if part is not None else capability_part(spec_dir, model)
    return Generation(capability, the_part, model, params_dir, spec_dir, workdir, out_dir, walks, walk_steps,
                      jobs).run()


def register(sub):
    add_command(sub, "vectors",
                lambda a: (generate(Path(a.model), Path(a.params), Path(a.spec), Path(a.work),
                                    Path(a.out), a.walks, a.walk_steps, a.jobs), 0)[1],
                "derive conformance vectors (trap goals, boundaries, random walks)",
                model={"required": True},
                params="directory with the generated <model>_params.pml",
                spec="spec/ directory (registry, schemas, justifications)",
                work={"required": True},
                out="output directory for <model>*.jsonl and <model>.coverage.json",
                walks={"type": int, "default": 50, "help": "random walks in the default configuration"},
                walk_steps={"type": int, "default": None,
                            "help": "length of each random walk in SPIN statements, for models whose "
                                    "walks are bounded that way (default: the capability's)"},
                jobs={"type": int, "default": os.cpu_count() or 1})
