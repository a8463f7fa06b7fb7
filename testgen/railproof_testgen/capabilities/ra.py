"""Conformance vectors of models/ra.pml (spec/design/ra.md §5, the re-adhesion
state machine: detection, parallel start points, re-adhesion judgement, maximum
compensation time, margin in force, sensor failure, stop demand).

Same technique as the braking and moving-block vectors (br_vectors.py, mb_vectors.py): one
trap property per `// @goal` (BFS: the shortest run reaching it, replayed with `spin -t`);
goals whose label names a boundary are the boundary vectors; then seeded random walks of
MODEL_CYCLES cycles (configuration WALK). Two machine configurations, each in a file of
its own whose header records it: readhesion.jsonl (two parallel start points, the default
configuration of the model) and readhesion.one_start.jsonl (one start point, the model's
ONE_START variant). A goal is searched in the configuration its annotation names; every
goal of the default configuration is also searched in ONE_START, and each one reached
there adds a vector to the one-start file (coverage entry "variant_vectors").

Units: model ticks are cycles and the model's margins are fed to the C++ as mm unchanged
(header "units"): the machine only compares ages with t_max and takes minima and maxima of
the limits, so the abstract values are exact. Files are checked line by line against
spec/schemas/vectors_ra.schema.json before they are written.
A goal that the exhaustive search cannot reach must be justified in spec/justifications.
"""
from __future__ import annotations

import re
import shutil
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from .. import __version__
from .. import spin as spin_mod
from ..errors import PipelineError, SpecError
from ..vectors import _progress, load_justifications, search_goal, write_configuration_files, write_goals_file
from ..vectors import model_bounds as _bounds

# ra::Mode and ra::StopReason in order, named as their ToString
MODES = ["TG", "COMPENSATING", "STOPPED"]
REASONS = ["NONE", "MAX_COMPENSATION_TIME", "IMU_FAILURE", "TG_FAILURE"]
# the model's section kinds in order (S_LONG, S_STEEP, S_SHORT)
SECTIONS = ["NORMAL", "STEEP", "TIGHT"]
NO_CANDIDATE = 255
BOUNDARY_WORDS = ("boundary",)
UNITS = "model ticks = cycles, model margin units = mm"
BOUNDS = ("confirm", "start_age", "search_extra", "spacing", "tmax_long", "tmax_short", "margin_long",
          "margin_steep", "margin_short", "cycles")
# configurations: model define (None = default) -> (file suffix, id tag, start points)
CONFIGS = {None: ("", "", 2), "ONE_START": (".one_start", "ONESTART-", 1)}

_RX_IN = re.compile(r"@IN cycle dev=([01]) sa0=([01]) sa1=([01]) imu=([01]) tg=([01]) bal=([01]) "
                    r"sec=(\d+) age=(\d+)")
_RX_OUT = re.compile(r"@OUT mode=(\d+) reason=(\d+) dcount=(\d+) a0=([01]) t0=(\d+) c0=(\d+) "
                     r"a1=([01]) t1=(\d+) c1=(\d+) tmax=(\d+) margin=(\d+) stop=([01]) valid=([01]) "
                     r"det=([01]) adopted=(\d+) breset=([01])")
_OUT_KEYS = ("mode", "reason", "dcount", "a0", "t0", "c0", "a1", "t1", "c1", "tmax", "margin", "stop",
             "valid", "det", "adopted", "breset")


def parse_events(text: str):
    """Replay/simulation output -> list of (inputs, outputs) per cycle, raw model integers.
    A cycle is complete with its @OUT line; a cycle cut off by the end of a trail or walk is
    dropped."""
    events, pending = [], None
    for line in text.splitlines():
        if "@IN" not in line and "@OUT" not in line:
            continue
        if m := _RX_IN.search(line):
            pending = {"dev": m[1] == "1", "sa": [m[2] == "1", m[3] == "1"], "imu": m[4] == "1",
                       "tg": m[5] == "1", "bal": m[6] == "1", "sec": int(m[7]), "age": int(m[8])}
        elif m := _RX_OUT.search(line):
            if pending is None:
                raise PipelineError(f"@OUT without its @IN cycle: {line.strip()}")
            events.append((pending, {k: int(v) for k, v in zip(_OUT_KEYS, m.groups())}))
            pending = None
        else:
            raise PipelineError(f"unrecognised model output line: {line.strip()}")
    return events


def section_limits(b: dict):
    """Section kind -> (T_s cycles, M_s mm), from the model bounds."""
    return [(b["tmax_long"], b["margin_long"]), (b["tmax_long"], b["margin_steep"]),
            (b["tmax_short"], b["margin_short"])]


def to_steps(events, b: dict):
    """Raw cycles -> vector steps (spec/schemas/vectors_ra.schema.json)."""
    limits = section_limits(b)
    steps = []
    for i, o in events:
        if i["sec"] >= len(SECTIONS) or o["mode"] >= len(MODES) or o["reason"] >= len(REASONS):
            raise PipelineError(f"model output outside the known sections, modes or reasons: {i} {o}")
        if o["adopted"] not in (0, 1, NO_CANDIDATE):
            raise PipelineError(f"unknown adopted candidate {o['adopted']} in the model output")
        t_s, m_s = limits[i["sec"]]
        steps.append({
            "in": {"deviation": i["dev"], "speed_agrees": list(i["sa"]), "imu_ok": i["imu"], "tg_ok": i["tg"],
                   "balise": i["bal"],
                   "section": {"kind": SECTIONS[i["sec"]], "max_compensation_cycles": t_s, "margin_mm": m_s},
                   "start_age_cycles": i["age"]},
            "out": {"mode": MODES[o["mode"]], "stop_reason": REASONS[o["reason"]],
                    "deviation_count": o["dcount"],
                    "candidates": [{"active": bool(o[f"a{c}"]), "age_cycles": o[f"t{c}"], "confirm": o[f"c{c}"]}
                                   for c in (0, 1)],
                    "max_compensation_cycles": o["tmax"], "margin_mm": o["margin"],
                    "stop_demand": bool(o["stop"]), "position_valid": bool(o["valid"]),
                    "detected": bool(o["det"]),
                    "adopted": None if o["adopted"] == NO_CANDIDATE else o["adopted"],
                    "balise_reset": bool(o["breset"])}})
    return steps


def observed_requirements(steps):
    """Requirements evidenced by what a run shows (added to the goal's own). Every step
    compares the margin and maximum compensation time in force (REQ-RA-009)."""
    reqs = {"REQ-RA-009"} if steps else set()
    for s in steps:
        i, o = s["in"], s["out"]
        if o["detected"]:
            reqs.add("REQ-RA-003")
            if o["candidates"][0]["active"]:
                reqs.add("REQ-RA-004")
            if sum(c["active"] for c in o["candidates"]) == 2:
                reqs.add("REQ-RA-010")
        if o["adopted"] is not None:
            reqs.update(["REQ-RA-006", "REQ-RA-010"])
        if o["stop_reason"] == "MAX_COMPENSATION_TIME":
            reqs.add("REQ-RA-007")
        if o["stop_reason"] in ("IMU_FAILURE", "TG_FAILURE") and (not i["imu_ok"] or not i["tg_ok"]):
            reqs.add("REQ-RA-013")
        if o["balise_reset"]:
            reqs.add("REQ-RA-012")
    return reqs


def header_for(model: Path, b: dict, config):
    _suffix, _tag, start_points = CONFIGS[config]
    limits = section_limits(b)
    return {
        "kind": "header", "schema_version": 1, "model": f"models/{model.name}",
        "model_sha256": spin_mod.sha256_file(model), "generator": f"railproof_testgen {__version__}",
        "spin_version": spin_mod.spin_version(), "configuration": config or "default",
        "units": UNITS, "unit_scales": {"cycles_per_tick": 1, "mm_per_margin_unit": 1},
        "parameters": {
            # ra::MachineConfig of the replay
            "confirm_cycles": b["confirm"], "start_points": start_points, "spacing_cycles": b["spacing"],
            # the environment of the model (documentation of the vectors' range)
            "start_age_cycles": [b["start_age"], b["start_age"] + b["search_extra"]],
            "sections": [{"kind": k, "max_compensation_cycles": t, "margin_mm": m}
                         for k, (t, m) in zip(SECTIONS, limits)],
            "model_cycles": b["cycles"],
            "modes": MODES, "stop_reasons": REASONS},
    }


def _vid(kind: str, config, tail: str) -> str:
    return f"RA-{kind.upper()}-{CONFIGS[config][1]}{tail}"


def generate(model: Path, params_dir: Path, spec_dir: Path, workdir: Path, out_dir: Path,
             walks: int = 50, jobs: int = 2):
    model = Path(model)
    model_rel = f"models/{model.name}"
    ann = spin_mod.parse_annotations(model)
    if not ann.goals:
        raise SpecError(model, "-", "no // @goal annotations: nothing to generate")
    for g in ann.goals:
        if g.config not in CONFIGS:
            raise SpecError(model, g.gid, f"goal names unknown configuration {g.config}")
    b = _bounds(Path(params_dir) / f"{model.stem}_params.pml")
    for key in BOUNDS:
        if key not in b:
            raise SpecError(Path(params_dir) / f"{model.stem}_params.pml", f"MODEL_{key.upper()}",
                            "model bound missing (spec/parameters/ra.yaml model_bounds)")
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    goals_file = workdir / f"{model.stem}_goals.pml"
    write_goals_file(ann, goals_file)
    bases = {}
    for cfg in CONFIGS:
        _progress(f"compiling trap model [{cfg or 'default'}] ({len(ann.goals)} goals)")
        bases[cfg] = spin_mod.prepare(model, params_dir, workdir / f"traps-{cfg or 'default'}",
                                      ["TRAPS"] + ([cfg] if cfg else []), [goals_file])

    # (goal, configuration): each goal in its own configuration, the default ones in ONE_START too
    searches = [(g, g.config) for g in ann.goals]
    searches += [(g, c) for g in ann.goals if g.config is None for c in CONFIGS if c]

    def run_goal(job):
        g, cfg = job
        defs = ["TRAPS"] + ([cfg] if cfg else [])
        return (g, cfg, *search_goal(model, bases[cfg], workdir, g, defs, parse_events))

    with ThreadPoolExecutor(max_workers=max(1, jobs)) as ex:
        outcomes = list(ex.map(run_goal, searches))

    justifications = load_justifications(spec_dir, model_rel)
    per_config = {c: [] for c in CONFIGS}
    coverage, problems, made = {}, [], {}
    for g, cfg, status, events, res in outcomes:
        home = cfg == g.config
        if status == "reached":
            kind = "boundary" if any(w in g.label.lower() for w in BOUNDARY_WORDS) else "trap"
            steps = to_steps(events, b)
            vid = made[(g.gid, cfg)] = _vid(kind, cfg, g.gid)
            per_config[cfg].append({"id": vid, "requirements": sorted(set(g.requirements) |
                                                                     observed_requirements(steps)),
                                    "goal": g.gid, "kind": kind, "seed": None, "steps": steps})
            _progress(f"{g.gid} [{cfg or 'default'}] reached in {len(steps)} cycle(s): {g.label}")
        else:
            _progress(f"{g.gid} [{cfg or 'default'}] UNREACHABLE ({res['states_stored']} states searched)"
                      f"{'' if home else ' (variant search)'}: {g.label}")
        if home:
            just = justifications.get(g.gid)
            if status == "unreachable" and not just:
                problems.append(f"goal {g.gid} ({g.label}) is unreachable and has no justification in "
                                f"spec/justifications/ (model {model_rel})")
            coverage[g.gid] = {"id": g.gid, "label": g.label, "requirements": g.requirements, "status": status,
                               "configuration": g.config or "default",
                               "vectors": [vid] if status == "reached" else [],
                               "justification": just if status == "unreachable" else None,
                               "states_searched": res["states_stored"] if status == "unreachable" else None}
    for g, cfg, status, _events, _res in outcomes:
        if cfg != g.config and status == "reached":
            entry = coverage[g.gid]
            entry.setdefault("variant_vectors", []).append(made[(g.gid, cfg)])
            entry["variant"] = cfg
    unreachable = {gid for gid, c in coverage.items() if c["status"] == "unreachable"}
    for gid in sorted(set(justifications) - unreachable):
        problems.append(f"justification {justifications[gid]} names goal {gid}, which is reached or unknown")

    def walk(job):
        seed, cfg = job
        # spin writes scratch files into its working directory: one directory per walk
        wd = workdir / f"walk{seed}-{cfg or 'default'}"
        if wd.exists():
            shutil.rmtree(wd)
        wd.mkdir()
        for f in bases[None].glob("*.pml"):
            shutil.copy2(f, wd / f.name)
        dflags = ["-DWALK"] + ([f"-D{cfg}"] if cfg else [])
        r = spin_mod._run(["spin", *dflags, f"-n{seed}", model.name], wd, timeout=300)
        if r.returncode != 0:
            raise PipelineError(f"spin simulation seed {seed} [WALK {cfg or ''}] failed: {r.stderr[-1000:]}")
        events = parse_events(r.stdout)
        if len(events) != b["cycles"]:
            raise PipelineError(f"random walk seed {seed} [{cfg or 'default'}] produced {len(events)} cycles, "
                                f"expected MODEL_CYCLES = {b['cycles']}")
        return seed, cfg, events

    n_other = max(1, walks // 5)
    jobs_list = [(seed, None) for seed in range(1, walks + 1)]
    jobs_list += [(seed, c) for c in CONFIGS if c for seed in range(1, n_other + 1)]
    _progress(f"{len(jobs_list)} random walks of {b['cycles']} cycles ({walks} with two start points, "
              f"{n_other} with one)")
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as ex:
        walked = list(ex.map(walk, jobs_list))
    for seed, cfg, events in walked:
        steps = to_steps(events, b)
        per_config[cfg].append({"id": _vid("random", cfg, f"S{seed}"),
                                "requirements": sorted(observed_requirements(steps)),
                                "goal": None, "kind": "random", "seed": seed, "steps": steps})
    return write_configuration_files(model, model_rel, ann, coverage, per_config,
                                     {c: v[0] for c, v in CONFIGS.items()},
                                     lambda cfg: header_for(model, b, cfg),
                                     Path(spec_dir) / "schemas" / "vectors_ra.schema.json", out_dir, problems)
