"""Conformance vectors of models/br.pml (spec/design/br.md §4, the supervision
decision: brake-level selection, emergency-brake latch and release).

Same technique as the telegram and moving-block vectors (vectors.py, mb_vectors.py): one
trap property per `// @goal` (BFS: the shortest run reaching it, replayed with `spin -t`);
goals whose label names a boundary are the boundary vectors (v_s exactly at and one above
a pattern speed); then seeded random walks of MODEL_CYCLES cycles (configuration WALK).

Units: the model's speeds are abstract integers 0..MODEL_VMAX; the vectors carry them
unchanged and the conformance harness feeds them to br::Supervisor as mm/s. This is
exact because the decision only compares the supervised speed with the pattern speeds
(header "units"). One file, braking.jsonl (schema spec/schemas/vectors_br.schema.json),
checked line by line before it is written, and braking.coverage.json.
A goal that the exhaustive search cannot reach must be justified in spec/justifications.
"""
from __future__ import annotations

import json
import re
import shutil
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from .. import __version__
from .. import spin as spin_mod
from ..errors import PipelineError, SpecError
from ..vectors import _atomic_write, _progress, load_justifications, schema_checked_jsonl, search_goal, \
    write_goals_file
from ..vectors import model_bounds as _bounds

# br::BrakeLevel in order, named as br::ToString
LEVELS = ["NONE", "4N", "5N", "6N", "7N", "EB"]
# the model's pattern speeds p0..p5 in the order of br::PatternSpeeds
PATTERNS = ["v_e", "v_7n", "v_6n", "v_5n", "v_4n", "v_release"]
BOUNDARY_WORDS = ("boundary",)
UNITS = "abstract speed units = mm/s"
# requirement evidenced by observing an output level in a run
LEVEL_REQS = {"NONE": ["REQ-BR-003"], "4N": ["REQ-BR-003"], "5N": ["REQ-BR-003"], "6N": ["REQ-BR-003"],
              "7N": ["REQ-BR-002"], "EB": ["REQ-BR-001", "REQ-BR-006"]}

_RX_CYCLE = re.compile(r"@IN cycle vs=(\d+) st=([01]) he=([01]) rs=([01])")
_RX_PICK = re.compile(r"@IN p(\d)=(\d+)")
_RX_OUT = re.compile(r"@OUT level=(\d) appr=([01]) latched=([01])")


def parse_events(text: str):
    """Replay/simulation output -> list of (inputs, outputs) per cycle. A cycle is complete
    with its @OUT line; a cycle cut off by the end of a trail or walk is dropped."""
    events, pending = [], None
    for line in text.splitlines():
        if "@IN" not in line and "@OUT" not in line:
            continue
        if m := _RX_CYCLE.search(line):
            pending = {"v_s": int(m[1]), "standstill": m[2] == "1", "handle_emergency": m[3] == "1",
                       "reset": m[4] == "1"}
        elif m := _RX_PICK.search(line):
            k = int(m[1])
            if pending is None or k >= len(PATTERNS) or PATTERNS[k] in pending:
                raise PipelineError(f"pattern speed outside a cycle or repeated: {line.strip()}")
            pending[PATTERNS[k]] = int(m[2])
        elif m := _RX_OUT.search(line):
            if pending is None or any(p not in pending for p in PATTERNS):
                raise PipelineError(f"@OUT without a complete @IN cycle: {line.strip()}")
            events.append((pending, {"level": int(m[1]), "appr": m[2] == "1", "latched": m[3] == "1"}))
            pending = None
        else:
            raise PipelineError(f"unrecognised model output line: {line.strip()}")
    return events


def to_steps(events):
    """Raw cycles -> vector steps (spec/schemas/vectors_br.schema.json)."""
    steps = []
    for i, o in events:
        if o["level"] >= len(LEVELS):
            raise PipelineError(f"unknown brake level {o['level']} in the model output")
        steps.append({"in": {"v_s": i["v_s"], **{p: i[p] for p in PATTERNS},
                             "standstill": i["standstill"], "handle_emergency": i["handle_emergency"],
                             "reset": i["reset"]},
                      "out": {"level": LEVELS[o["level"]], "pattern_approaching": o["appr"],
                              "emergency_latched": o["latched"]}})
    return steps


def observed_requirements(steps):
    reqs = set()
    for s in steps:
        reqs.update(LEVEL_REQS[s["out"]["level"]])
        if s["out"]["pattern_approaching"]:
            reqs.add("REQ-BR-003")
    return reqs


def header_for(model: Path, b: dict):
    return {
        "kind": "header", "schema_version": 1, "model": f"models/{model.name}",
        "model_sha256": spin_mod.sha256_file(model), "generator": f"railproof_testgen {__version__}",
        "spin_version": spin_mod.spin_version(), "configuration": "default",
        "units": UNITS, "unit_scales": {"speed_mm_s_per_unit": 1},
        "parameters": {"model_vmax": b["vmax"], "model_cycles": b["cycles"], "levels": LEVELS},
    }


def generate(model: Path, params_dir: Path, spec_dir: Path, workdir: Path, out_dir: Path,
             walks: int = 50, jobs: int = 2):
    model = Path(model)
    model_rel = f"models/{model.name}"
    ann = spin_mod.parse_annotations(model)
    if not ann.goals:
        raise SpecError(model, "-", "no // @goal annotations: nothing to generate")
    b = _bounds(Path(params_dir) / f"{model.stem}_params.pml")
    for key in ("vmax", "cycles"):
        if key not in b:
            raise SpecError(Path(params_dir) / f"{model.stem}_params.pml", f"MODEL_{key.upper()}",
                            "model bound missing (spec/parameters/br.yaml model_bounds)")
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    goals_file = workdir / f"{model.stem}_goals.pml"
    write_goals_file(ann, goals_file)
    _progress(f"compiling trap model ({len(ann.goals)} goals)")
    base = spin_mod.prepare(model, params_dir, workdir / "traps", ["TRAPS"], [goals_file])

    def run_goal(g):
        return (g, *search_goal(model, base, workdir, g, ["TRAPS"], parse_events))

    with ThreadPoolExecutor(max_workers=max(1, jobs)) as ex:
        outcomes = list(ex.map(run_goal, ann.goals))

    justifications = load_justifications(spec_dir, model_rel)
    vectors, coverage, problems = [], [], []
    for g, status, events, res in outcomes:
        vec_ids = []
        if status == "reached":
            kind = "boundary" if any(w in g.label.lower() for w in BOUNDARY_WORDS) else "trap"
            steps = to_steps(events)
            vid = f"BR-{kind.upper()}-{g.gid}"
            vectors.append({"id": vid, "requirements": sorted(set(g.requirements) | observed_requirements(steps)),
                            "goal": g.gid, "kind": kind, "seed": None, "steps": steps})
            vec_ids.append(vid)
            _progress(f"{g.gid} reached in {len(steps)} cycle(s): {g.label}")
        else:
            _progress(f"{g.gid} UNREACHABLE ({res['states_stored']} states searched): {g.label}")
        just = justifications.get(g.gid)
        if status == "unreachable" and not just:
            problems.append(f"goal {g.gid} ({g.label}) is unreachable and has no justification in "
                            f"spec/justifications/ (model {model_rel})")
        coverage.append({"id": g.gid, "label": g.label, "requirements": g.requirements, "status": status,
                         "configuration": "default", "vectors": vec_ids,
                         "justification": just if status == "unreachable" else None,
                         "states_searched": res["states_stored"] if status == "unreachable" else None})
    for gid in sorted(set(justifications) - {c["id"] for c in coverage if c["status"] == "unreachable"}):
        problems.append(f"justification {justifications[gid]} names goal {gid}, which is reached or unknown")

    def walk(seed):
        # spin writes scratch files into its working directory: one directory per walk
        wd = workdir / f"walk{seed}"
        if wd.exists():
            shutil.rmtree(wd)
        wd.mkdir()
        for f in base.glob("*.pml"):
            shutil.copy2(f, wd / f.name)
        r = spin_mod._run(["spin", "-DWALK", f"-n{seed}", model.name], wd, timeout=300)
        if r.returncode != 0:
            raise PipelineError(f"spin simulation seed {seed} [WALK] failed: {r.stderr[-1000:]}")
        events = parse_events(r.stdout)
        if len(events) != b["cycles"]:
            raise PipelineError(f"random walk seed {seed} produced {len(events)} cycles, "
                                f"expected MODEL_CYCLES = {b['cycles']}")
        return seed, events

    _progress(f"{walks} random walks of {b['cycles']} cycles each")
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as ex:
        walked = list(ex.map(walk, range(1, walks + 1)))
    for seed, events in walked:
        steps = to_steps(events)
        vectors.append({"id": f"BR-RANDOM-S{seed}", "requirements": sorted(observed_requirements(steps)),
                        "goal": None, "kind": "random", "seed": seed, "steps": steps})
    vectors.sort(key=lambda v: (v["kind"] == "random", v["kind"] == "trap", _order(v["id"])))

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    name = f"{model.stem}.jsonl"
    schema = Path(spec_dir) / "schemas" / "vectors_br.schema.json"
    text = schema_checked_jsonl(schema, [header_for(model, b), *vectors], name)
    reached = sum(1 for c in coverage if c["status"] == "reached")
    cov = {"schema": "railproof/coverage/1", "model": model_rel, "goals": coverage, "reached": reached,
           "labelled": len(coverage), "unreachable_justified": sum(
               1 for c in coverage if c["status"] == "unreachable" and c["justification"]),
           "vectors": {k: sum(v["kind"] == k for v in vectors) for k in ("trap", "boundary", "random")},
           "files": {name: len(vectors)}}
    _atomic_write(out_dir / name, text)
    _atomic_write(out_dir / f"{model.stem}.coverage.json", json.dumps(cov, indent=2, sort_keys=True) + "\n")
    _progress(f"goal coverage {reached}/{len(coverage)} reached, {cov['unreachable_justified']} "
              f"unreachable justified; {len(vectors)} vectors written")
    if problems:
        raise PipelineError(f"{model.name}: " + "; ".join(problems))
    return cov


def _order(vid: str):
    """Sort key: numeric part of G<k> / S<seed> ids."""
    m = re.search(r"(\d+)$", vid)
    return (vid[: m.start()] if m else vid, int(m.group(1)) if m else 0)
