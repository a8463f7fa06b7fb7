"""Derive conformance vectors from a SPIN model.

Three kinds of vectors (spec/design/tg.md §7, schema spec/schemas/vectors_tg.schema.json):
- trap: every `// @goal K` becomes a trap property `[] !g[K]`; pan (BFS) returns the
  shortest run that reaches the goal, whose replayed @IN/@OUT lines are the vector.
  Goals whose label names a boundary, edge or wrap-around are the boundary vectors.
- random: seeded random walks (`spin -n<seed> -u<steps>`); the seed is in the id.
Each run of the model is emitted once per endpoint role (ground, train): the logic is
the same, the identifiers, telegram types and safe-reaction output differ.
A goal that the exhaustive search cannot reach must be justified in spec/justifications.
"""
from __future__ import annotations

import json
import os
import re
import shutil
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import jsonschema

from . import __version__
from . import spin as spin_mod
from .errors import PipelineError, SpecError
from .spec import load_yaml

VERDICTS = ["ACCEPT", "REJ_INTEGRITY", "REJ_ADDRESS", "REJ_AUTH", "REJ_REPEATED", "REJ_SEQUENCE",
            "REJ_NO_ECHO", "REJ_UNKNOWN_ECHO", "REJ_STALE"]
LINKS = ["NONE", "UP", "LOST"]
NONE = 255
# delivery modes of the model (D_INTACT ... D_MISADDR)
MODE_INTACT, MODE_DUP, MODE_CORRUPT, MODE_FORGE, MODE_MISADDR = range(5)

# requirement evidenced by observing a verdict / transition in a run
VERDICT_REQS = {
    "ACCEPT": ["REQ-TG-008"], "REJ_INTEGRITY": ["REQ-TG-005"], "REJ_ADDRESS": ["REQ-TG-003"],
    "REJ_AUTH": ["REQ-TG-007"], "REJ_REPEATED": ["REQ-TG-001"], "REJ_SEQUENCE": ["REQ-TG-004"],
    "REJ_NO_ECHO": ["REQ-TG-012"], "REJ_UNKNOWN_ECHO": ["REQ-TG-008"],
    "REJ_STALE": ["REQ-TG-006", "REQ-TG-009"],
}
LOST_REQS = ["REQ-TG-013", "REQ-TG-014", "REQ-TG-015"]
BOUNDARY_WORDS = ("boundary", "edge", "wrap")

_IN_TICK = re.compile(r"@IN tick")
_IN_RX = re.compile(r"@IN rx seq=(\d+) echo=(\d+) mode=(\d+)")
_OUT_TX = re.compile(r"@OUT tx seq=(\d+) echo=(\d+) link=(\d+) eb=(\d+) abnormal=(\d+)")
_OUT_RX = re.compile(r"@OUT rx verdict=(\d+) gap=(\d+) link=(\d+) eb=(\d+) abnormal=(\d+)")


def parse_events(text: str):
    """Turn replay/simulation output into a list of raw (input, output) events."""
    events, pending = [], None
    for line in text.splitlines():
        if m := _IN_TICK.search(line):
            pending = {"ev": "tick"}
        elif m := _IN_RX.search(line):
            pending = {"ev": "rx", "seq": int(m[1]), "echo": int(m[2]), "mode": int(m[3])}
        elif m := _OUT_TX.search(line):
            if pending is None or pending["ev"] != "tick":
                raise PipelineError(f"@OUT tx without @IN tick: {line.strip()}")
            events.append((pending, {"seq": int(m[1]), "echo": int(m[2]), "link": int(m[3]),
                                     "eb": int(m[4]), "abnormal": int(m[5])}))
            pending = None
        elif m := _OUT_RX.search(line):
            if pending is None or pending["ev"] != "rx":
                raise PipelineError(f"@OUT rx without @IN rx: {line.strip()}")
            events.append((pending, {"verdict": int(m[1]), "gap": int(m[2]), "link": int(m[3]),
                                     "eb": int(m[4]), "abnormal": int(m[5])}))
            pending = None
    # an input whose output was cut off by the end of a trail is dropped
    return events


def _role_out(role, o):
    base = {"link": LINKS[o["link"]]}
    if role == "train":
        base["eb"] = bool(o["eb"])
    else:
        base["tracking"] = "ABNORMAL" if o["abnormal"] else "TRACKED"
    return base


def to_steps(events, role, ids):
    """Map raw events to the vector step format of one endpoint role."""
    steps = []
    own, peer, other = (ids["ground_id"], ids["train_id"], ids["other_train_id"])
    for i, o in events:
        if i["ev"] == "tick":
            out = {"tx": {"seq": o["seq"], "echo": None if o["echo"] == NONE else o["echo"]}}
            out.update(_role_out(role, o))
            steps.append({"in": {"ev": "tick"}, "out": out})
            continue
        mode = i["mode"]
        if role == "ground":
            src, dst, typ = peer, own, "POSITION"
            if mode == MODE_MISADDR:
                src = other
        else:
            src, dst, typ = own, peer, "CONTROL"
            if mode == MODE_MISADDR:
                dst = other
        tg = {"src": src, "dst": dst, "type": typ, "seq": i["seq"],
              "echo": None if i["echo"] == NONE else i["echo"],
              "auth": "nokey" if mode == MODE_FORGE else "key",
              "integrity": "corrupt" if mode == MODE_CORRUPT else "ok"}
        out = {"verdict": VERDICTS[o["verdict"]], "gap": o["gap"]}
        out.update(_role_out(role, o))
        steps.append({"in": {"ev": "rx", "tg": tg}, "out": out})
    return steps


def observed_requirements(events):
    reqs = set()
    prev_link = 0
    for i, o in events:
        if i["ev"] == "rx":
            reqs.update(VERDICT_REQS[VERDICTS[o["verdict"]]])
        if prev_link == 1 and o["link"] == 2:
            reqs.update(LOST_REQS)
        prev_link = o["link"]
    return reqs


ROLES = ("ground", "train")


def vectors_for_roles(stem, events, ids, requirements, goal, kind, seed):
    """One run of the model becomes one vector per endpoint role (same logic, the
    identifiers, telegram types and safe-reaction output differ)."""
    return [{"id": f"{stem}-{role}", "role": role, "requirements": requirements, "goal": goal,
             "kind": kind, "seed": seed, "steps": to_steps(events, role, ids)} for role in ROLES]


def search_goal(model: Path, base: Path, workdir: Path, g, defines, parser=None):
    """Run the trap property of goal g on a copy of the compiled pan in `base`; return
    (status, events, pan results): reached with the replayed run, or unreachable."""
    tag = "".join(f"-{d}" for d in defines if d != "TRAPS")
    wd = workdir / f"goal{g.number}{tag}"
    if wd.exists():
        shutil.rmtree(wd)
    shutil.copytree(base, wd)
    r = spin_mod._run(["./pan", "-N", f"goal{g.number}"], wd)
    res = spin_mod.parse_pan(r.stdout + r.stderr)
    if res["errors"]:
        rep = spin_mod._run(["spin", *[f"-D{d}" for d in defines], "-t", model.name], wd, timeout=300)
        events = (parser or parse_events)(rep.stdout)
        if not events:
            raise PipelineError(f"{model.name}: goal {g.gid}{tag} trail replay produced no events:\n"
                                f"{rep.stdout[-2000:]}")
        return "reached", events, res
    if res["incomplete"]:
        raise PipelineError(f"{model.name}: goal {g.gid}{tag}: search incomplete "
                            f"({'; '.join(res['incomplete'])})")
    return "unreachable", None, res


def write_goals_file(ann, path: Path):
    lines = ["/* Generated by railproof_testgen vectors: one trap property per coverage goal. */"]
    for g in ann.goals:
        lines.append(f"ltl goal{g.number} {{ [] !g[{g.number}] }}")
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def load_justifications(spec_dir: Path, model_rel: str):
    out = {}
    jdir = Path(spec_dir) / "justifications"
    for f in sorted(jdir.glob("*.yaml")) if jdir.exists() else []:
        data = load_yaml(f)
        for e in data.get("justifications") or []:
            if e.get("model") == model_rel:
                out[str(e.get("goal"))] = e["id"]
    return out


def _progress(msg):
    print(f"vectors: {msg}", flush=True)


def model_bounds(params_pml: Path):
    """The model bounds of a generated <model>_params.pml, keyed without their "model_"
    prefix (shared by the moving-block and braking generators)."""
    raw = spin_mod.read_bounds(params_pml)
    return {k[len("model_"):] if k.startswith("model_") else k: v for k, v in raw.items()}


def generate(model: Path, params_dir: Path, spec_dir: Path, workdir: Path, out_dir: Path,
             walks: int = 50, walk_steps: int = 7000, jobs: int = 2):
    model = Path(model)
    if model.stem == "mb":
        from .capabilities import mb as mb_vectors
        return mb_vectors.generate(model, params_dir, spec_dir, workdir, out_dir, walks, jobs)
    if model.stem == "br":
        from .capabilities import br as br_vectors
        return br_vectors.generate(model, params_dir, spec_dir, workdir, out_dir, walks, jobs)
    if model.stem == "ra":
        from .capabilities import ra as ra_vectors
        return ra_vectors.generate(model, params_dir, spec_dir, workdir, out_dir, walks, jobs)
    if model.stem == "lc":
        from .capabilities import lc as lc_vectors
        return lc_vectors.generate(model, params_dir, spec_dir, workdir, out_dir, walks, jobs)
    model_rel = f"models/{model.name}"
    ann = spin_mod.parse_annotations(model)
    if not ann.goals:
        raise SpecError(model, "-", "no // @goal annotations: nothing to generate")
    params_pml = Path(params_dir) / f"{model.stem}_params.pml"
    bounds = spin_mod.read_bounds(params_pml)
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    goals_file = workdir / f"{model.stem}_goals.pml"
    write_goals_file(ann, goals_file)
    _progress(f"compiling trap model ({len(ann.goals)} goals)")
    base = spin_mod.prepare(model, params_dir, workdir / "traps", ["TRAPS"], [goals_file])

    def run_goal(g):
        return (g, *search_goal(model, base, workdir, g, ["TRAPS"]))

    with ThreadPoolExecutor(max_workers=max(1, jobs)) as ex:
        outcomes = list(ex.map(run_goal, ann.goals))

    justifications = load_justifications(spec_dir, model_rel)
    ids = {"ground_id": bounds["ground_id"], "train_id": bounds["train_id"],
           "other_train_id": bounds["other_train_id"]}
    vectors, coverage, problems = [], [], []
    for g, status, events, res in outcomes:
        vec_ids = []
        if status == "reached":
            kind = "boundary" if any(w in g.label.lower() for w in BOUNDARY_WORDS) else "trap"
            reqs = sorted(set(g.requirements) | observed_requirements(events))
            made = vectors_for_roles(f"TG-{kind.upper()}-{g.gid}", events, ids, reqs, g.gid, kind, None)
            vec_ids.extend(v["id"] for v in made)
            vectors.extend(made)
            _progress(f"{g.gid} reached in {len(events)} steps: {g.label}")
        else:
            _progress(f"{g.gid} UNREACHABLE ({res['states_stored']} states searched): {g.label}")
        just = justifications.get(g.gid)
        if status == "unreachable" and not just:
            problems.append(f"goal {g.gid} ({g.label}) is unreachable and has no justification in "
                            f"spec/justifications/ (model {model_rel})")
        coverage.append({"id": g.gid, "label": g.label, "requirements": g.requirements, "status": status,
                         "vectors": vec_ids, "justification": just if status == "unreachable" else None,
                         "states_searched": res["states_stored"] if status == "unreachable" else None})
    # Boundary variants: goals unreachable in the main configuration are searched again in
    # each variant; a goal reached there yields vectors in a file of its own, whose header
    # carries the variant's parameter.
    variant_files = {}
    unreachable = [g for g, status, _, _ in outcomes if status == "unreachable"]
    for v in ann.variants if unreachable else []:
        _progress(f"variant {v.define}: searching {len(unreachable)} goal(s) unreachable in the main configuration")
        vbase = spin_mod.prepare(model, params_dir, workdir / f"traps-{v.define}", ["TRAPS", v.define], [goals_file])
        vvecs = []
        for g in unreachable:
            status, events, _res = search_goal(model, vbase, workdir, g, ["TRAPS", v.define])
            if status != "reached":
                _progress(f"{g.gid} unreachable in {v.define} too")
                continue
            reqs = sorted(set(g.requirements) | observed_requirements(events))
            suffix = v.define.lower().replace("variant_", "").replace("_", "")
            vvecs.extend(vectors_for_roles(f"TG-BOUNDARY-{g.gid}{suffix}", events, ids, reqs, g.gid,
                                           "boundary", None))
            cov_entry = next(c for c in coverage if c["id"] == g.gid)
            cov_entry.setdefault("variant_vectors", []).extend(x["id"] for x in vvecs[-len(ROLES):])
            cov_entry["variant"] = v.define
            _progress(f"{g.gid} reached in variant {v.define} in {len(events)} steps")
        if vvecs:
            if v.bound not in bounds:
                raise SpecError(model, v.define, f"variant names unknown model bound {v.bound}")
            variant_files[v.define.lower()] = (v, vvecs)
    for gid in sorted(set(justifications) - {c["id"] for c in coverage if c["status"] == "unreachable"}):
        problems.append(f"justification {justifications[gid]} names goal {gid}, which is reached or unknown")

    _progress(f"{walks} random walks of {walk_steps} SPIN statements each")
    sim_dir = workdir / "traps"

    def walk(seed, config=None):
        # spin writes scratch files into its working directory: one directory per walk
        wd = workdir / f"walk{seed}{'-' + config if config else ''}"
        if wd.exists():
            shutil.rmtree(wd)
        wd.mkdir()
        for f in sim_dir.glob("*.pml"):
            shutil.copy2(f, wd / f.name)
        dflags = [f"-D{config}"] if config else []
        r = spin_mod._run(["spin", *dflags, f"-n{seed}", f"-u{walk_steps}", model.name], wd, timeout=300)
        if r.returncode != 0:
            raise PipelineError(f"spin simulation seed {seed} failed: {r.stderr[-1000:]}")
        return seed, parse_events(r.stdout)

    with ThreadPoolExecutor(max_workers=max(1, jobs)) as ex:
        walks_out = list(ex.map(walk, range(1, walks + 1)))
    for seed, events in walks_out:
        if not events:
            raise PipelineError(f"random walk seed {seed} produced no events")
        reqs = sorted(observed_requirements(events))
        vectors.extend(vectors_for_roles(f"TG-RANDOM-S{seed}", events, ids, reqs, None, "random", seed))

    # Walks in the other configurations of the model (e.g. HEALTHY: a perfect channel),
    # evidence for the properties verified in that configuration.
    for config in sorted({c for p in ann.properties for c in p.configs if c}):
        creqs = sorted({r for p in ann.properties if config in p.configs for r in p.requirements})
        n_cfg = max(1, walks // 10)
        _progress(f"{n_cfg} random walks in configuration {config}")
        for seed in range(1, n_cfg + 1):
            _, events = walk(seed, config)
            if not events:
                raise PipelineError(f"random walk seed {seed} [{config}] produced no events")
            reqs = sorted(set(creqs) | observed_requirements(events))
            vectors.extend(vectors_for_roles(f"TG-RANDOM-{config}S{seed}", events, ids, reqs, None,
                                             "random", seed))

    header = {
        # the main configuration header (variants override one parameter)
        "kind": "header", "schema_version": 1, "model": model_rel,
        "model_sha256": spin_mod.sha256_file(model),
        "generator": f"railproof_testgen {__version__}", "spin_version": spin_mod.spin_version(),
        "unit_scales": {"time_ms_per_tick": bounds["tick_ms"]},
        "parameters": {
            "seq_modulus": bounds["seq_modulus"], "seq_window": bounds["seq_window"],
            "history_depth": bounds["history_depth"],
            "turnaround_ms": bounds["turnaround_ticks"] * bounds["tick_ms"],
            "link_timeout_ms": bounds["link_ticks"] * bounds["tick_ms"],
            "echo_validity_ms": bounds["echo_ticks"] * bounds["tick_ms"],
            "init_own_seq": bounds["init_own_seq"], "init_peer_seq": bounds["init_peer_seq"],
            **ids},
    }
    def checked(lines, name):
        return schema_checked_jsonl(Path(spec_dir) / "schemas" / "vectors_tg.schema.json", lines, name)

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    for old in out_dir.glob(f"{model.stem}.*.jsonl"):
        old.unlink()  # variant files of an earlier run
    for suffix, (v, vvecs) in sorted(variant_files.items()):
        vheader = json.loads(json.dumps(header))
        vheader["parameters"][v.parameter] = bounds[v.bound]
        vheader["variant"] = v.define
        name = f"{model.stem}.{suffix}.jsonl"
        _atomic_write(out_dir / name, checked([vheader, *vvecs], name))
    lines = [header, *vectors]
    reached = sum(1 for c in coverage if c["status"] == "reached")
    cov = {"schema": "railproof/coverage/1", "model": model_rel, "goals": coverage, "reached": reached,
           "labelled": len(coverage), "unreachable_justified": sum(
               1 for c in coverage if c["status"] == "unreachable" and c["justification"]),
           "vectors": {"trap": sum(v["kind"] == "trap" for v in vectors),
                       "boundary": sum(v["kind"] == "boundary" for v in vectors),
                       "random": sum(v["kind"] == "random" for v in vectors),
                       "variant_boundary": sum(len(vv) for _, vv in variant_files.values())}}
    _atomic_write(out_dir / f"{model.stem}.jsonl", checked(lines, f"{model.stem}.jsonl"))
    _atomic_write(out_dir / f"{model.stem}.coverage.json", json.dumps(cov, indent=2, sort_keys=True) + "\n")
    _progress(f"goal coverage {reached}/{len(coverage)} reached, "
              f"{cov['unreachable_justified']} unreachable justified; {len(vectors)} vectors written")
    if problems:
        raise PipelineError(f"{model.name}: " + "; ".join(problems))
    return cov


def _most_specific(err):
    """The deepest error under a oneOf/anyOf failure, so that a message names the field that
    is wrong (e.g. steps/0/onboard/in/reports/0: 'requesters' is a required property) instead
    of quoting the whole line."""
    while err is not None and err.context:
        err = max(err.context, key=lambda e: len(e.absolute_path))
    return err


def schema_checked_jsonl(schema_path: Path, lines, name: str) -> str:
    """Validate every line (header and vectors) against the JSON schema of the vector
    format and return the JSON Lines text; a line that violates it is a PipelineError naming
    the file, line and field (nothing is written). Shared by every vector generator."""
    schema = json.loads(Path(schema_path).read_text(encoding="utf-8"))
    validator = jsonschema.Draft202012Validator(schema)
    for n, obj in enumerate(lines, 1):
        err = _most_specific(jsonschema.exceptions.best_match(validator.iter_errors(obj)))
        if err:
            message = err.message if len(err.message) <= 300 else err.message[:300] + " ..."
            raise PipelineError(f"generated {name} line {n} violates the vector schema: "
                                f"{'/'.join(map(str, err.absolute_path)) or '(top level)'}: {message}")
    return "".join(json.dumps(o, sort_keys=True, separators=(",", ":")) + "\n" for o in lines)


def _atomic_write(path: Path, text: str):
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(path)


def _id_order(vid: str):
    """Sort key: numeric part of G<k> / S<seed> ids."""
    m = re.search(r"(\d+)$", vid)
    return (vid[: m.start()] if m else vid, int(m.group(1)) if m else 0)


def write_configuration_files(model: Path, model_rel: str, ann, coverage: dict, per_config: dict,
                              suffixes: dict, header_for, schema: Path, out_dir: Path,
                              problems: list) -> dict:
    """The shared end of the generators that write one vector file per model configuration
    (readhesion, level crossing): sort each file's vectors (boundary, trap, random; by goal
    or seed), check every line against the schema before anything is written, write the
    files and the coverage record atomically, remove the files of configurations no longer
    generated, and fail with the collected problems. suffixes: configuration -> file-name
    suffix; header_for(configuration) -> the file's header line."""
    for vecs in per_config.values():
        vecs.sort(key=lambda v: (v["kind"] == "random", v["kind"] == "trap", _id_order(v["id"])))
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    texts = {}
    for cfg, vecs in per_config.items():
        name = f"{model.stem}{suffixes[cfg]}.jsonl"
        texts[name] = schema_checked_jsonl(schema, [header_for(cfg), *vecs], name)
    all_vecs = [v for vecs in per_config.values() for v in vecs]
    cov_goals = [coverage[g.gid] for g in ann.goals]
    reached = sum(1 for c in cov_goals if c["status"] == "reached")
    cov = {"schema": "railproof/coverage/1", "model": model_rel, "goals": cov_goals, "reached": reached,
           "labelled": len(cov_goals), "unreachable_justified": sum(
               1 for c in cov_goals if c["status"] == "unreachable" and c["justification"]),
           "vectors": {k: sum(v["kind"] == k for v in all_vecs) for k in ("trap", "boundary", "random")},
           "files": {f"{model.stem}{suffixes[c]}.jsonl": len(v) for c, v in per_config.items()}}
    for old in out_dir.glob(f"{model.stem}.*.jsonl"):
        if old.name not in texts:
            old.unlink()  # a file of an earlier configuration set
    for name, text in texts.items():
        _atomic_write(out_dir / name, text)
    _atomic_write(out_dir / f"{model.stem}.coverage.json", json.dumps(cov, indent=2, sort_keys=True) + "\n")
    _progress(f"goal coverage {reached}/{len(cov_goals)} reached, {cov['unreachable_justified']} "
              f"unreachable justified; {len(all_vecs)} vectors written "
              f"({', '.join(f'{n}: {k}' for n, k in cov['files'].items())})")
    if problems:
        raise PipelineError(f"{model.name}: " + "; ".join(problems))
    return cov


def register(sub):
    p = sub.add_parser("vectors", help="derive conformance vectors (trap goals, boundaries, random walks)")
    p.add_argument("--model", required=True)
    p.add_argument("--params", required=True, help="directory with the generated <model>_params.pml")
    p.add_argument("--spec", required=True, help="spec/ directory (schemas, justifications)")
    p.add_argument("--work", required=True)
    p.add_argument("--out", required=True, help="output directory for <model>.jsonl and coverage")
    p.add_argument("--walks", type=int, default=50)
    p.add_argument("--walk-steps", type=int, default=7000,
                   help="length of each random walk in SPIN statements (about 60 per event)")
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    p.set_defaults(func=lambda a: (generate(Path(a.model), Path(a.params), Path(a.spec), Path(a.work),
                                            Path(a.out), a.walks, a.walk_steps, a.jobs), 0)[1])
