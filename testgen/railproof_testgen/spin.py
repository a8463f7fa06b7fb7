"""Run SPIN: exhaustive verification of every named property, and the mutant models.

`verify` compiles the model once per configuration (pan with -DBFS -DSAFETY: a complete
breadth-first search; for safety properties it is exhaustive and needs no depth bound) and
verifies every `// @property` of the configuration, then compiles and runs every
`// @mutant`, which must be rejected. Any violated or incomplete property fails the
command with the counterexample shown; so does a surviving mutant.

Every property of the models is an invariant, `ltl NAME { [] p }`. The properties of one
configuration are verified together in one search of the conjunction, `[] (p1 && p2 ...)`
(the claim `railproof_all`, appended to a copy of the model; [] (p1 && p2) holds exactly when
[] p1 and [] p2 hold), so the state space of a configuration is searched once instead of
once per property. If that search does not verify, every property of the configuration is
searched on its own, so a violation is reported against the property it breaks, with its
own counterexample. A configuration with one property, or with a property that is not of
the form `[] p`, is always searched per property. The compilations and searches of the
configurations and the mutants share one pool of `--jobs` workers, so that a configuration is
searched while the next one compiles.

The trap searches of vector generation (search_goals) live here too: all goals of one
configuration in one breadth-first search, each goal with the run its own trap property gives.
"""
from __future__ import annotations

import errno
import hashlib
import os
import re
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from . import add_command
from .errors import PipelineError, SpecError
from .files import write_json

_REQ_ID = r"REQ-[A-Z]{2}-\d{3}"
_REQ = re.compile(_REQ_ID)
_REQS = rf"((?:{_REQ_ID}\s*)+)"  # one or more requirement ids


def _annotation(tag, fields):
    """A `// @<tag> <fields>` line of a model (fields: the pattern after the tag)."""
    return re.compile(rf"^\s*//\s*@{tag}\s+{fields}$")


_PROP = _annotation("property", rf"(\w+)\s+{_REQS}:\s*(.*)")
_GOAL = _annotation("goal", rf"(\d+)\s+{_REQS}:\s*(.*)")
_MUT = _annotation("mutant", r"(\w+)\s+violates\s+(\S+)\s*:\s*(.*)")
_ASSERT = _annotation("assert", rf"(\w+)\s+{_REQS}:\s*(.*)")
_VARIANT = _annotation("variant", r"(\w+)(?:\s+(\w+)=(\w+))?\s*:\s*(.*)")
# an environment given to random walks only (neither verified nor searched: its counters are
# too large for an exhaustive search), e.g. a unit's environment at its real times
_WALKS = _annotation("walks", r"(\w+)\s*:\s*(.*)")
_CONFIG = re.compile(r"\[config\s+(\w+(?:\s+\w+)*)\]")
_PAN_FLAGS = _annotation("pan_flags", r"((?:-D\w+(?:=\w+)?\s*)+)")

PAN_FLAGS = ["-O2", "-DSAFETY", "-DBFS", "-DMEMLIM=8000"]

# an invariant claim on one line: ltl NAME { [] p }
_LTL_INVARIANT = re.compile(r"^\s*ltl\s+(\w+)\s*\{\s*\[\]\s*(.+?)\s*\}\s*(?://.*)?$", re.M)
COMBINED_CLAIM = "railproof_all"


def invariant_claims(model_text: str) -> dict:
    """{claim name: p} for every claim of the form `ltl NAME { [] p }` on one line."""
    return {m.group(1): m.group(2) for m in _LTL_INVARIANT.finditer(model_text)}


def combined_claim(bodies: list) -> str:
    """The conjunction of invariants as one claim (see the module docstring)."""
    return f"ltl {COMBINED_CLAIM} {{ [] ({' && '.join(f'({b})' for b in bodies)}) }}\n"


@dataclass
class Property:
    name: str
    requirements: list
    text: str
    config: str | None  # -D symbol of the (first) configuration, None = default
    configs: list = field(default_factory=list)  # every configuration it is verified in


@dataclass
class Goal:
    number: int
    requirements: list
    label: str
    config: str | None = None  # configuration the trap property is searched in (None = default)

    @property
    def gid(self):
        return f"G{self.number}"


@dataclass
class Mutant:
    name: str
    violates: str  # property name or "assert:<label>"
    text: str
    config: str | None = None  # configuration the mutant is checked in (None = default)


@dataclass
class Variant:
    define: str
    parameter: str | None  # vector header parameter it overrides (None: an environment variant)
    bound: str | None      # model bound (lower-case name without MODEL_) giving the new value
    text: str


@dataclass
class Annotations:
    model: Path
    properties: list = field(default_factory=list)
    goals: list = field(default_factory=list)
    mutants: list = field(default_factory=list)
    asserts: dict = field(default_factory=dict)
    variants: list = field(default_factory=list)  # label -> (variables of the expression, requirements, text)
    walk_only: list = field(default_factory=list)  # (define, text) of the // @walks configurations
    pan_flags: list = field(default_factory=list)  # extra -D flags for compiling pan (// @pan_flags)


def _assert_signature(expr: str) -> frozenset:
    """Identify an assertion by its variables (pan prints it with macros expanded)."""
    return frozenset(re.findall(r"\b[a-z_][a-z0-9_]*\b", expr))


def parse_annotations(model: Path) -> Annotations:
    model = Path(model)
    ann = Annotations(model)
    seen = set()
    lines = model.read_text(encoding="utf-8").splitlines()
    for lineno, line in enumerate(lines, 1):
        m = _PAN_FLAGS.match(line)
        if m:
            ann.pan_flags.extend(m.group(1).split())
            continue
        m = _VARIANT.match(line)
        if m:
            ann.variants.append(Variant(m.group(1), m.group(2), m.group(3), m.group(4).strip()))
            continue
        m = _WALKS.match(line)
        if m:
            ann.walk_only.append((m.group(1), m.group(2).strip()))
            continue
        m = _ASSERT.match(line)
        if m:
            nxt = lines[lineno] if lineno < len(lines) else ""
            am = re.match(r"^\s*assert\((.*)\);?\s*$", nxt)
            if not am:
                raise SpecError(model, f"line {lineno}", "@assert must be followed by an assert(...) line")
            ann.asserts[m.group(1)] = (_assert_signature(am.group(1)), _REQ.findall(m.group(2)), m.group(3).strip())
            continue
        for rx, kind in ((_PROP, "property"), (_GOAL, "goal"), (_MUT, "mutant")):
            m = rx.match(line)
            if not m:
                continue
            key = (kind, m.group(1))
            if key in seen:
                raise SpecError(model, f"line {lineno}", f"duplicate @{kind} {m.group(1)}")
            seen.add(key)
            if kind == "property":
                cfg = _CONFIG.search(m.group(3))
                cfgs = cfg.group(1).split() if cfg else [None]
                ann.properties.append(Property(m.group(1), _REQ.findall(m.group(2)), m.group(3).strip(),
                                               cfgs[0], cfgs))
            elif kind == "goal":
                label = m.group(3).strip()
                cfg = _CONFIG.search(label)
                if cfg:
                    label = _CONFIG.sub("", label).strip()
                ann.goals.append(Goal(int(m.group(1)), _REQ.findall(m.group(2)), label,
                                      cfg.group(1) if cfg else None))
            else:
                cfg = _CONFIG.search(m.group(3))
                if cfg and len(cfg.group(1).split()) != 1:
                    raise SpecError(model, m.group(1), "a mutant is checked in exactly one configuration")
                ann.mutants.append(Mutant(m.group(1), m.group(2), m.group(3).strip(),
                                          cfg.group(1) if cfg else None))
    if not ann.properties:
        raise SpecError(model, "-", "no // @property annotations")
    names = {p.name for p in ann.properties}
    for mu in ann.mutants:
        if mu.violates.startswith("assert:"):
            if mu.violates[7:] not in ann.asserts:
                raise SpecError(model, mu.name, f"mutant names unknown assertion {mu.violates}")
        elif mu.violates not in names:
            raise SpecError(model, mu.name, f"mutant names unknown property {mu.violates}")
    return ann


def sha256_file(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def spin_version() -> str:
    try:
        out = subprocess.run(["spin", "-V"], capture_output=True, text=True, check=False).stdout
    except FileNotFoundError:
        raise PipelineError("spin not found on PATH (install the Debian package 'spin')") from None
    return out.strip()


def read_bounds(params_pml: Path) -> dict:
    bounds = {}
    for line in Path(params_pml).read_text(encoding="utf-8").splitlines():
        m = re.match(r"#define\s+MODEL_(\w+)\s+(-?\d+)", line)
        if m:
            bounds[m.group(1).lower()] = int(m.group(2))
    return bounds


def _run(cmd, cwd, timeout=None):
    """Run a command. Executing a freshly linked ./pan can fail with ETXTBSY ("text file
    busy") while the thread pool forks another child that still holds the linker's write
    descriptor for a moment (seen under load in a fresh build); that is retried, anything
    else is raised."""
    for attempt in range(20):
        try:
            return subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout,
                                  check=False)
        except OSError as exc:
            if exc.errno != errno.ETXTBSY or attempt == 19:
                raise
            time.sleep(0.05 * (attempt + 1))
    raise AssertionError("unreachable")


# A model may include parts it shares with another model of its capability; they live in
# models/include/<cap>_*.pml (not models of their own) and are staged beside the model.
INCLUDE_DIR = "include"
_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def shared_includes(model: Path) -> list:
    """The files of models/include/ that the model includes (its shared parts)."""
    model = Path(model)
    inc_dir = model.parent / INCLUDE_DIR
    names = _INCLUDE.findall(model.read_text(encoding="utf-8"))
    return [inc_dir / n for n in names if (inc_dir / n).is_file()]


def model_text(model: Path) -> str:
    """The model and the shared parts it includes, as one text (for what testgen reads from
    the model's source, e.g. its local bounds)."""
    return "\n".join(Path(f).read_text(encoding="utf-8") for f in [Path(model), *shared_includes(model)])


def params_file(params_dir: Path, model: Path) -> Path:
    """The generated parameter header of a model: <cap>_params.pml of its capability (a model
    is named <cap> or <cap>_<part>, spec/capabilities.yaml)."""
    cap = Path(model).stem.split("_")[0]
    path = Path(params_dir) / f"{cap}_params.pml"
    if not path.is_file():
        raise PipelineError(f"{path}: missing: the generated parameters of {Path(model).name} "
                            f"(spec/parameters/{cap}.yaml)")
    return path


def stage(model: Path, params_dir: Path, workdir: Path, extra_claim: str | None = None, texts=None):
    """A fresh workdir with a copy of the model (extra_claim, a claim, appended to it), the
    shared parts it includes (models/include), its generated includes (the *.pml of params_dir)
    and the files of texts ({name: text})."""
    workdir = Path(workdir)
    if workdir.exists():
        shutil.rmtree(workdir)
    workdir.mkdir(parents=True)
    shutil.copy2(model, workdir / Path(model).name)
    for inc in shared_includes(model):
        shutil.copy2(inc, workdir / inc.name)
    if extra_claim:
        with open(workdir / Path(model).name, "a", encoding="utf-8") as f:
            f.write("\n" + extra_claim)
    for inc in Path(params_dir).glob("*.pml"):
        shutil.copy2(inc, workdir / inc.name)
    for name, text in (texts or {}).items():
        (workdir / name).write_text(text, encoding="utf-8")
    return workdir


def prepare(model: Path, params_dir: Path, workdir: Path, defines=(), extra_files=(), cflags=None,
            extra_claim: str | None = None, texts=None):
    """Stage the model in workdir (see stage), copy extra_files there, run spin -a and
    compile pan (PAN_FLAGS, then cflags: by default the model's // @pan_flags)."""
    workdir = stage(model, params_dir, workdir, extra_claim, texts)
    for f in extra_files:
        shutil.copy2(f, workdir / Path(f).name)
    dflags = [f"-D{d}" for d in defines]
    r = _run(["spin", *dflags, "-a", Path(model).name], workdir)
    if r.returncode != 0 or not (workdir / "pan.c").exists():
        raise PipelineError(f"spin -a {' '.join(dflags)} {model} failed:\n{r.stdout}{r.stderr}")
    if cflags is None:
        cflags = parse_annotations(model).pan_flags
    r = _run(["cc", *PAN_FLAGS, *cflags, "-o", "pan", "pan.c"], workdir)
    if r.returncode != 0:
        raise PipelineError(f"compiling pan for {model} {' '.join(dflags)} failed:\n{r.stderr[-4000:]}")
    return workdir


_NUM = r"([0-9.e+]+)"


def parse_pan(out: str) -> dict:
    def grab(rx, conv=float, default=None):
        m = re.search(rx, out)
        return conv(m.group(1)) if m else default

    res = {
        "errors": grab(r"errors:\s*(\d+)", int),
        "states_stored": grab(rx=r"\n\s*" + _NUM + r" states, stored", conv=lambda s: int(float(s))),
        "states_matched": grab(r"\n\s*" + _NUM + r" states, matched", lambda s: int(float(s))),
        "transitions": grab(r"\n\s*" + _NUM + r" transitions", lambda s: int(float(s))),
        "depth": grab(r"depth reached (\d+)", int),
        "state_vector_bytes": grab(r"State-vector (\d+) byte", int),
        "memory_mb": grab(r"([0-9.]+)\s+total actual memory usage"),
        "time_s": grab(r"pan: elapsed time ([0-9.e+]+)"),
    }
    incomplete = []
    if "max search depth too small" in out:
        incomplete.append("search depth bound reached")
    if "out of memory" in out.lower() or "pan: reached -DMEMLIM" in out:
        incomplete.append("out of memory")
    if "Full statespace search" not in out and res["errors"] == 0:
        incomplete.append("no full state-space search reported")
    res["incomplete"] = incomplete
    m = re.search(r"assertion violated (.*?) \(at depth", out)
    res["violated_expression"] = _assert_signature(m.group(1)) if m else None
    return res


def counterexample(workdir: Path, model_name: str, defines=()) -> str:
    """Replay the trail and return the @IN/@OUT lines (and the last raw lines)."""
    dflags = [f"-D{d}" for d in defines]
    r = _run(["spin", *dflags, "-t", model_name], workdir, timeout=120)
    lines = [ln.strip() for ln in r.stdout.splitlines() if "@IN" in ln or "@OUT" in ln]
    tail = [ln for ln in r.stdout.splitlines() if ln.strip()][-6:]
    return "\n".join(lines + ["..."] + tail)


# ---- trap searches: the runs that vectors are derived from ---------------------------------------
GOALS_CLAIM = "railproof_goals"
_FILTER_INSTALL = "railproof_first_hits.h"
_FIRST = re.compile(r"^railproof: first reached:((?: \d+)+)$")
_WROTE = re.compile(r"^pan: wrote (\S+\.trail)$")
_PAN_ERROR = re.compile(r"^pan:\d+: (.*)$")


def goals_file(model: Path) -> str:
    """The file a model includes under -DTRAPS (its `#include "<model>_goals.pml"`)."""
    return f"{Path(model).stem}_goals.pml"


def goals_claim(numbers) -> str:
    """The trap claim of a search: no goal of the set is ever reached, `[] !(g[K1] || g[K2] ...)`,
    as a claim of one state with one step (an assertion), so that the product with the model
    has the states of the model and pan explores them in the order of a single trap property."""
    return (f"never {GOALS_CLAIM} {{\n"
            f"  do :: assert(!({' || '.join(f'g[{k}]' for k in numbers)})) od\n}}\n")


def first_hits_filter(numbers) -> str:
    """C code of the goals file: pan's error report (uerror) is wrapped so that a violation of
    the trap claim is reported, with its trail, only at the first state whose goal flags show
    a goal not reported before; the search ends once every goal is reported. A violation in a
    state without any goal flag of the search set (a model assertion) is reported as it is."""
    n = len(numbers)
    return f"""/* Generated by railproof_testgen (spin.search_goals): the first violation of each goal only. */
c_code {{
extern void (*uerror)(char *);
void wrapup(void);
static void (*railproof_report)(char *);
static const int railproof_goal[{n}] = {{{", ".join(map(str, numbers))}}};
static unsigned char railproof_found[{n}];
static int railproof_left = {n};
static void railproof_first_hits(char *msg)
{{	int i, any = 0, fresh = 0;
	for (i = 0; i < {n}; i++)
	{{	if (!now.g[railproof_goal[i]]) continue;
		any = 1;
		if (railproof_found[i]) continue;
		if (!fresh) printf("railproof: first reached:");
		printf(" %d", railproof_goal[i]);
		railproof_found[i] = 1;
		railproof_left--;
		fresh = 1;
	}}
	if (any && !fresh) return; /* a goal reported before */
	printf(fresh ? "\\n" : "railproof: not a goal\\n");
	railproof_report(msg);
	if (fresh && railproof_left == 0) wrapup();
}}
}}
"""


@dataclass
class GoalSearch:
    """One breadth-first search of a configuration for a set of goals (search_goals)."""
    dir: Path
    model: str                 # file name of the model
    defines: list
    trails: dict               # goal number -> trail file (in dir) of its first violation
    res: dict                  # pan's statistics (parse_pan)

    def replay(self, trail: str, workdir: Path) -> str:
        """`spin -t` of one trail of the search, in workdir of its own (spin writes scratch
        files): the model copy with the trap claim, its includes, a goals file without the C
        code (spin does not run it) and the trail. Returns spin's output."""
        wd = Path(workdir)
        if wd.exists():
            shutil.rmtree(wd)
        wd.mkdir(parents=True)
        for f in self.dir.glob("*.pml"):
            shutil.copy2(f, wd / f.name)
        (wd / goals_file(self.model)).write_text("/* trap claim replay: no C code */\n", encoding="utf-8")
        shutil.copy2(self.dir / trail, wd / f"{self.model}.trail")
        r = _run(["spin", *[f"-D{d}" for d in self.defines], "-t", self.model], wd, timeout=300)
        if r.returncode != 0:
            raise PipelineError(f"{self.model}: replay of {trail} [{' '.join(self.defines)}] failed:\n"
                                f"{r.stdout[-1000:]}{r.stderr[-1000:]}")
        return r.stdout


def search_goals(model: Path, params_dir: Path, workdir: Path, defines, numbers, pan_flags=None) -> GoalSearch:
    """Search the goals `numbers` of a model (flags g[K], set by its GOAL(K) under -DTRAPS) in
    one configuration with one breadth-first search, and keep for each goal the trail of the
    first state of the search that reaches it.

    This gives each goal the trail that its own trap property `[] !g[K]` gives (the trap
    technique: pan -DBFS stops at the first violation, a shortest run). pan's breadth-first
    order depends only on the model and on a claim's steps, not on what the claim tests: the
    claim of one state and one step (goals_claim) has the same product with the model as
    each goal's own claim up to that goal's first violation, so the search meets every state
    in the same order, with the same parent, and the first state that reaches goal K is the
    state where K's own search stops. Its violations are filtered (first_hits_filter, put in
    place by pan's provisioning hook -DPROV) so that only the first one of each goal writes a
    trail (pan -c0 -e). A goal without a trail is unreachable in the configuration, provided
    the search is complete (checked). The claim is appended to the copy of the model, after
    its processes (a model may include its goals file before them); the goals file holds the
    C code."""
    model = Path(model)
    numbers = list(numbers)
    if not numbers:
        raise PipelineError(f"{model.name} [{' '.join(defines)}]: a trap search needs goals")
    if f'#include "{goals_file(model)}"' not in model.read_text(encoding="utf-8"):
        raise SpecError(model, "TRAPS", f'the model does not #include "{goals_file(model)}" (its goal flags g[K] '
                                        f'are searched with the trap claim and C code of that file)')
    if pan_flags is None:
        pan_flags = parse_annotations(model).pan_flags
    wd = prepare(model, params_dir, workdir, defines, cflags=[*pan_flags, f'-DPROV="{_FILTER_INSTALL}"'],
                 extra_claim=goals_claim(numbers),
                 texts={goals_file(model): first_hits_filter(numbers),
                        _FILTER_INSTALL: "railproof_report = uerror; uerror = railproof_first_hits;\n"})
    r = _run(["./pan", "-N", GOALS_CLAIM, "-c0", "-e"], wd)
    out = r.stdout + r.stderr
    res = parse_pan(out)
    where = f"{model.name} [{' '.join(defines)}]"
    if res["errors"] is None:
        raise PipelineError(f"{where}: trap search: unexpected output of pan:\n{out[-2000:]}")
    trails, others, pending, message = {}, [], None, ""
    for line in out.splitlines():
        if m := _FIRST.match(line):
            pending = [int(k) for k in m.group(1).split()]
        elif line == "railproof: not a goal":
            pending = "other"
        elif m := _PAN_ERROR.match(line):
            message = m.group(1)
        elif (m := _WROTE.match(line)) and pending is not None:
            if pending == "other":
                others.append(f"{message} (trail {m.group(1)})")
            else:
                trails.update({k: m.group(1) for k in pending})
            pending = None
    if others:
        raise PipelineError(f"{where}: the trap model is violated outside its goals: " + "; ".join(others))
    if set(trails) != set(numbers) and res["incomplete"]:
        raise PipelineError(f"{where}: trap search incomplete ({'; '.join(res['incomplete'])}); goals not "
                            f"reached: {', '.join(f'G{k}' for k in numbers if k not in trails)}")
    return GoalSearch(wd, model.name, list(defines), trails, res)


def _progress(msg):
    print(f"spin: {msg}", flush=True)


def verify(model: Path, params_dir: Path, workdir: Path, out_json: Path, jobs: int = 2) -> dict:
    model = Path(model)
    ann = parse_annotations(model)
    version = spin_version()
    bounds = read_bounds(params_file(params_dir, model))
    # every default-configuration property is also verified in every boundary variant
    runs = [(p, c) for p in ann.properties for c in p.configs]
    runs += [(p, v.define) for v in ann.variants for p in ann.properties if p.config is None]
    configs = sorted({c for _, c in runs}, key=lambda c: c or "")
    t0 = time.monotonic()
    claims = invariant_claims(model.read_text(encoding="utf-8"))
    in_config = {c: [p for p, rc in runs if rc == c] for c in configs}
    # configurations searched once for the conjunction of their properties
    combined = {c: ps for c, ps in in_config.items() if len(ps) > 1 and all(p.name in claims for p in ps)}
    dirs = {}
    pan_cc = f"cc {' '.join(PAN_FLAGS + ann.pan_flags)} -o pan pan.c"

    def run_claim(claim: str, config, tag: str):
        # each run in its own copy of the binary's directory: pan writes the trail there
        wd = Path(workdir) / f"prop-{tag}-{config or 'default'}"
        if wd.exists():
            shutil.rmtree(wd)
        shutil.copytree(dirs[config], wd)
        r = _run(["./pan", "-N", claim], wd)
        res = parse_pan(r.stdout + r.stderr)
        if res["errors"] is None:
            raise PipelineError(f"{model.name}: pan -N {claim}: unexpected output:\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
        verdict = "verified"
        cex = None
        if res["errors"]:
            verdict = "violated"
            cex = counterexample(wd, model.name, [config] if config else [])
        elif res["incomplete"]:
            verdict = "incomplete"
        return verdict, cex, res

    def record(p, config, verdict, cex, res, command, extra=None):
        return {"name": p.name, "requirements": p.requirements, "text": p.text,
                "configuration": config or "default", "verdict": verdict, "command": command,
                "counterexample": cex, **(extra or {}),
                **{k: v for k, v in res.items() if k != "violated_expression"}}

    def run_prop(run):
        p, config = run
        verdict, cex, res = run_claim(p.name, config, p.name)
        _progress(f"{p.name} [{config or 'default'}]: {verdict} ({res['states_stored']} states, "
                  f"depth {res['depth']}, {res['time_s']} s)")
        return record(p, config, verdict, cex, res,
                      f"spin {'-D' + config + ' ' if config else ''}-a {model.name} && {pan_cc} && ./pan -N {p.name}")

    def run_combined(config):
        ps = combined[config]
        verdict, _cex, res = run_claim(COMBINED_CLAIM, config, COMBINED_CLAIM)
        names = [p.name for p in ps]
        _progress(f"{len(ps)} properties together [{config or 'default'}]: {verdict} "
                  f"({res['states_stored']} states, depth {res['depth']}, {res['time_s']} s)")
        if verdict != "verified":
            return config, None
        claim = combined_claim([claims[n] for n in names]).strip()
        stem = model.stem
        command = (f"(cat {model.name}; echo '{claim}') > {stem}_all.pml && "
                   f"spin {'-D' + config + ' ' if config else ''}-a {stem}_all.pml && {pan_cc} && "
                   f"./pan -N {COMBINED_CLAIM}")
        return config, [record(p, config, verdict, None, res, command,
                               {"verified_with": [n for n in names if n != p.name]}) for p in ps]

    def check_config(config):
        """Compile the configuration, then search its properties (together or one by one)."""
        name = config or "default"
        _progress(f"compiling {model.name} [{name}]")
        extra = combined_claim([claims[p.name] for p in combined[config]]) if config in combined else None
        dirs[config] = prepare(model, params_dir, Path(workdir) / f"verify-{name}", [config] if config else [],
                               extra_claim=extra)
        if config in combined:
            return run_combined(config)
        return config, [run_prop((p, config)) for p in in_config[config]]

    def run_mutant(mu: Mutant):
        mdefs = [mu.name] + ([mu.config] if mu.config else [])
        wd = prepare(model, params_dir, Path(workdir) / f"mutant-{mu.name}", mdefs)
        claim = mu.violates if not mu.violates.startswith("assert:") else ann.properties[0].name
        r = _run(["./pan", "-N", claim], wd)
        res = parse_pan(r.stdout + r.stderr)
        model_asserts = {expr for expr, _, _ in ann.asserts.values()}
        violated = res["violated_expression"]
        violated = next((a for a in model_asserts if violated is not None and a <= violated), violated)
        if mu.violates.startswith("assert:"):
            rejected = bool(res["errors"]) and violated == ann.asserts[mu.violates[7:]][0]
        else:  # the claim itself must fire, not a model assertion
            rejected = bool(res["errors"]) and violated not in model_asserts
        _progress(f"mutant {mu.name}: {'rejected' if rejected else 'SURVIVED'}")
        return {"name": mu.name, "property": mu.violates, "text": mu.text, "expect": "rejected",
                "configuration": mu.config or "default",
                "verdict": "rejected" if rejected else "survived",
                "errors": res["errors"], "states_stored": res["states_stored"], "depth": res["depth"],
                "time_s": res["time_s"],
                "counterexample": counterexample(wd, model.name, mdefs) if rejected else None}

    single = [(p, c) for p, c in runs if c not in combined]
    _progress(f"verifying {len(ann.properties)} properties in {len(configs)} configuration(s): "
              f"{len(combined)} combined searches and {len(single)} single-property searches, then "
              f"{len(ann.mutants)} mutant models, with {jobs} job(s)")
    # one pool for the compilations and the searches: a configuration's searches follow its
    # compilation, the mutants follow the configurations
    results = {}
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as ex:
        config_futures = [ex.submit(check_config, c) for c in configs]
        mutant_futures = [ex.submit(run_mutant, mu) for mu in ann.mutants]
        for f in config_futures:
            config, recs = f.result()
            if recs is None:  # search every property of the configuration on its own
                _progress(f"[{config or 'default'}]: not verified together; searching per property")
                recs = list(ex.map(run_prop, [(p, config) for p in combined[config]]))
            for r in recs:
                results[(r["name"], config)] = r
        mutants = [f.result() for f in mutant_futures]
    props = [results[(p.name, c)] for p, c in runs]

    # Every pan run checks every assert(...) of the model in the states it explores (no
    # -A), so a named assertion is verified when every run completed without error.
    all_clean = all(p["errors"] == 0 and not p["incomplete"] for p in props)
    assertions = [{"name": f"assert:{label}", "requirements": reqs, "text": text,
                   "verdict": "verified" if all_clean else
                   ("violated" if any(p["errors"] for p in props) else "incomplete"),
                   "runs": len({(p["configuration"], p["command"]) for p in props}),
                   "basis": "checked in every verification run of every configuration listed in properties"}
                  for label, (_expr, reqs, text) in sorted(ann.asserts.items())]
    result = {
        "schema": "railproof/spin-results/1",
        "model": f"models/{model.name}",
        "model_sha256": sha256_file(model),
        "spin_version": version,
        "pan_flags": PAN_FLAGS + ann.pan_flags,
        "bounds": bounds,
        "properties": props,
        "assertions": assertions,
        "variants": [{"define": v.define, "parameter": v.parameter, "bound": v.bound, "text": v.text}
                     for v in ann.variants],
        "walk_only": [{"define": d, "text": t} for d, t in ann.walk_only],
        "mutants": mutants,
        "wall_time_s": round(time.monotonic() - t0, 1),
    }
    out_json = Path(out_json)
    write_json(out_json, result, if_changed=False)

    failures = [p for p in props if p["verdict"] != "verified"]
    survivors = [m for m in mutants if m["verdict"] != "rejected"]
    if failures or survivors:
        msg = []
        for p in failures:
            msg.append(f"property {p['name']} ({', '.join(p['requirements'])}) [{p['configuration']}] {p['verdict']}"
                       + (f": {'; '.join(p['incomplete'])}" if p["incomplete"] else "")
                       + (f"\ncounterexample:\n{p['counterexample']}" if p["counterexample"] else ""))
        for m in survivors:
            msg.append(f"mutant {m['name']} survived: property {m['property']} was not violated")
        raise PipelineError(f"{model.name}: " + "\n".join(msg))
    return result


def register(sub):
    add_command(sub, "verify",
                lambda a: (verify(Path(a.model), Path(a.params), Path(a.work), Path(a.out), a.jobs), 0)[1],
                "model-check every named property and every mutant of a model",
                model={"required": True},
                params="directory with the generated <model>_params.pml",
                work="scratch directory (build tree)", out="results JSON",
                jobs={"type": int, "default": os.cpu_count() or 1})



if __name__ == "__main__":  # pragma: no cover
    sys.exit("use: python -m railproof_testgen verify ...")
