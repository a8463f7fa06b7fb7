"""Conformance vectors of models/mb.pml (spec/design/mb.md §6).

Same technique as the telegram vectors (vectors.py): one trap property per `// @goal`
(BFS: the shortest run reaching it, replayed), goals whose label names a boundary are the
boundary vectors, then seeded random walks in the full configuration and in the CORE and
FAIR verification configurations. The model's units and ticks are turned into mm and ms
(design note §2), so the vectors drive the C++ ground and on-board units directly.
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

NOTEL = -9
KINDS = ["NONE", "PRECEDING_TRAIN", "FIXED_BLOCK", "ROUTE_END", "HANDOVER", "SYSTEM_BOUNDARY",
         "POSSESSION", "ABNORMAL_TRAIN", "END_OF_TRACK"]
VERDICTS = ["ACCEPT", "TOO_OLD", "NOT_NEWER"]
COMMANDS = {1: "POSSESSION_REQUEST", 2: "POSSESSION_CANCEL", 3: "SIDING_REQUEST", 4: "SIDING_FREE",
            5: "SECURE", 6: "BOUNDARY_ACCEPT"}
POSSESSION = ["NONE", "REQUESTED", "ACTIVE"]
BOUNDARY_WORDS = ("boundary", "edge")
# requirement evidenced by observing an output in a run
KIND_REQS = {"PRECEDING_TRAIN": ["REQ-MB-006"], "FIXED_BLOCK": ["REQ-MB-006"],
             "ROUTE_END": ["REQ-MB-006", "REQ-MB-013"], "HANDOVER": ["REQ-MB-006", "REQ-MB-017"],
             "SYSTEM_BOUNDARY": ["REQ-MB-006", "REQ-MB-023"], "POSSESSION": ["REQ-MB-006", "REQ-MB-014"],
             "ABNORMAL_TRAIN": ["REQ-MB-006", "REQ-MB-004"], "END_OF_TRACK": ["REQ-MB-006", "REQ-MB-023"]}
# walks in these configurations of the model (full = no define)
WALK_CONFIGS = (None, "TRIO", "FAIR")

_RX = {
    "env_in": re.compile(r"@IN env cmd=(\d+) arg=(\d+)"),
    "env_out": re.compile(r"@OUT env poss=(\d+) side_req=(\d+)"),
    "rep_in": re.compile(r"@IN report t=(\d+) front=(\d+) ext=(\d+)"),
    "rep_out": re.compile(r"@OUT report t=(\d+) tracked=(\d+)"),
    "tick_in": re.compile(r"@IN tick"),
    "train_out": re.compile(r"@OUT train t=(\d+) grant=(-?\d+) why=(\d+) abn=(\d+) usable=(\d+)"),
    "il_out": re.compile(r"@OUT il main=(\d+) side=(\d+) pts=(\d+) poss=(\d+) occ=(\d+)"),
    "dl_in": re.compile(r"@IN deliver t=(\d+) lim=(-?\d+) age=(\d+)"),
    "dl_out": re.compile(r"@OUT ob t=(\d+) verdict=(\d+) lim=(-?\d+)"),
}


def parse_events(text: str):
    """Replay/simulation output -> list of raw (input, output) events; a tick's output is
    complete only with its `@OUT il` line (an input cut off by the end of a trail is dropped)."""
    events, pending, trains = [], None, []
    for line in text.splitlines():
        if "@IN" not in line and "@OUT" not in line:
            continue
        if m := _RX["env_in"].search(line):
            pending = {"ev": "cmd", "cmd": int(m[1]), "arg": int(m[2])}
        elif m := _RX["rep_in"].search(line):
            pending = {"ev": "report", "t": int(m[1]), "front": int(m[2]), "ext": int(m[3])}
        elif _RX["tick_in"].search(line):
            pending, trains = {"ev": "tick"}, []
        elif m := _RX["dl_in"].search(line):
            pending = {"ev": "deliver", "t": int(m[1]), "lim": int(m[2]), "age": int(m[3])}
        elif m := _RX["env_out"].search(line):
            _expect(pending, "cmd", line)
            events.append((pending, {"poss": int(m[1]), "side_req": int(m[2])}))
            pending = None
        elif m := _RX["rep_out"].search(line):
            _expect(pending, "report", line)
            events.append((pending, {"tracked": int(m[2])}))
            pending = None
        elif m := _RX["train_out"].search(line):
            _expect(pending, "tick", line)
            trains.append({"t": int(m[1]), "grant": int(m[2]), "why": int(m[3]), "abn": int(m[4]),
                           "usable": int(m[5])})
        elif m := _RX["il_out"].search(line):
            _expect(pending, "tick", line)
            events.append((pending, {"trains": trains, "main": int(m[1]), "side": int(m[2]),
                                     "pts": int(m[3]), "poss": int(m[4]), "occ": int(m[5])}))
            pending, trains = None, []
        elif m := _RX["dl_out"].search(line):
            _expect(pending, "deliver", line)
            events.append((pending, {"verdict": int(m[2]), "lim": int(m[3])}))
            pending = None
        else:
            raise PipelineError(f"unrecognised model output line: {line.strip()}")
    return events


def _expect(pending, ev, line):
    if pending is None or pending["ev"] != ev:
        raise PipelineError(f"@OUT without its @IN {ev}: {line.strip()}")


class Scale:
    """Model units and ticks -> mm and ms (design note §2)."""

    def __init__(self, b):
        self.b = b
        self.S = b["unit_mm"]
        self.T = b["tick_ms"]

    def front(self, f):
        return (f + 1) * self.S

    def limit(self, lim):
        return None if lim == NOTEL else (lim + 1) * self.S

    def section(self, lo, hi):
        return [lo * self.S, (hi + 1) * self.S]


def to_steps(events, sc: Scale):
    steps = []
    accepted = set()  # trains whose on-board unit holds an accepted authority
    for i, o in events:
        ev = i["ev"]
        if ev == "cmd":
            cmd = COMMANDS[i["cmd"]]
            steps.append({"in": {"ev": "cmd", "cmd": cmd, "train": i["arg"] if cmd == "SECURE" else None},
                          "out": {"possession": POSSESSION[o["poss"]], "siding_requested": bool(o["side_req"])}})
        elif ev == "report":
            steps.append({"in": {"ev": "report", "train": i["t"], "front_mm": sc.front(i["front"]),
                                 "correction_mm": i["ext"] * sc.S},
                          "out": {"tracked": bool(o["tracked"])}})
        elif ev == "tick":
            trains = [{"limit_mm": sc.limit(t["grant"]) if t["abn"] else (t["grant"] + 1) * sc.S,
                       "kind": KINDS[t["why"]], "abnormal": bool(t["abn"]),
                       "authority_usable": bool(t["usable"])}
                      for t in sorted(o["trains"], key=lambda x: x["t"])]
            occupied = [b for b in range(sc.b["blocks"]) if o["occ"] >> b & 1]
            steps.append({"in": {"ev": "tick"},
                          "out": {"trains": trains, "main_route": bool(o["main"]), "siding_route": bool(o["side"]),
                                  "points_reverse": bool(o["pts"]), "possession": POSSESSION[o["poss"]],
                                  "occupied": occupied}})
        else:
            verdict = VERDICTS[o["verdict"]]
            if verdict == "ACCEPT":
                accepted.add(i["t"])
            steps.append({"in": {"ev": "deliver", "train": i["t"], "limit_mm": (i["lim"] + 1) * sc.S,
                                 "age_ms": i["age"] * sc.T},
                          "out": {"verdict": verdict,
                                  "limit_mm": (o["lim"] + 1) * sc.S if i["t"] in accepted else None}})
    return steps


def observed_requirements(steps):
    reqs = set()
    for s in steps:
        ev, out = s["in"]["ev"], s["out"]
        if ev == "report":
            reqs.update(["REQ-MB-001", "REQ-MB-003"])
        elif ev == "deliver":
            reqs.add("REQ-MB-009")
        elif ev == "cmd":
            cmd = s["in"]["cmd"]
            reqs.add({"POSSESSION_REQUEST": "REQ-MB-014", "POSSESSION_CANCEL": "REQ-MB-014",
                      "SIDING_REQUEST": "REQ-MB-012", "SIDING_FREE": "REQ-MB-012",
                      "SECURE": "REQ-MB-017", "BOUNDARY_ACCEPT": "REQ-MB-023"}[cmd])
        else:
            reqs.update(["REQ-MB-010", "REQ-MB-024"])
            for t in out["trains"]:
                reqs.update(KIND_REQS.get(t["kind"], []))
                if t["abnormal"]:
                    reqs.add("REQ-MB-004")
    return reqs


def header_for(model: Path, b: dict, config):
    sc = Scale(b)
    S = sc.S
    nt = {"CORE": 2, "FEATURE_POSS": 2, "FEATURE_ROUTE": 2, "FEATURE_RADIO": 2}.get(config, b["trains"])
    preset = config in ("CORE", "FAIR", "FEATURE_POSS", "FEATURE_ROUTE")
    return {
        "kind": "header", "schema_version": 1, "model": f"models/{model.name}",
        "model_sha256": spin_mod.sha256_file(model), "generator": f"railproof_testgen {__version__}",
        "spin_version": spin_mod.spin_version(), "configuration": config or "default",
        "unit_scales": {"time_ms_per_tick": sc.T, "mm_per_unit": S},
        "parameters": {
            "line_mm": b["line_units"] * S,
            "blocks_mm": [k * b["block_units"] * S for k in range(b["blocks"] + 1)],
            "platform_mm": sc.section(b["platform_first_unit"], b["platform_last_unit"]),
            "points_mm": sc.section(b["points_first_unit"], b["points_last_unit"]),
            "route_main_mm": sc.section(b["points_first_unit"], b["route_last_unit"]),
            "possession_mm": sc.section(b["possession_first_unit"], b["possession_last_unit"]),
            "handover_mm": b["handover_unit"] * S, "boundary_mm": b["boundary_unit"] * S,
            "margins_mm": {k: b[f"margin_{k}"] * S for k in
                           ("train", "fixed_block", "route", "handover", "boundary", "possession",
                            "abnormal", "eot")},
            "train_length_mm": b["train_units"] * S,
            "initial_front_mm": [sc.front(b[f"init_front_{k}"]) for k in range(nt)],
            "initial_correction_mm": [_ext(b, b[f"init_front_{k}"]) * S for k in range(nt)],
            "tracking_timeout_ms": b["track_timeout_ticks"] * sc.T,
            "validity_ms": b["link_ticks"] * sc.T, "max_age_ms": b["max_age_ticks"] * sc.T,
            "secured_at_start": preset or config == "FEATURE_POSS",
            "boundary_accepted_at_start": preset,
        },
    }


def _ext(b, p):
    e = (p % b["balise_spacing_units"]) // b["odo_units_per_ext"]
    return min(e, b["ext_max"])


def generate(model: Path, params_dir: Path, spec_dir: Path, workdir: Path, out_dir: Path,
             walks: int = 40, jobs: int = 2, walk_steps: int = 3000):
    model = Path(model)
    model_rel = f"models/{model.name}"
    ann = spin_mod.parse_annotations(model)
    if not ann.goals:
        raise SpecError(model, "-", "no // @goal annotations: nothing to generate")
    b = _bounds(Path(params_dir) / f"{model.stem}_params.pml")
    sc = Scale(b)
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    goals_file = workdir / f"{model.stem}_goals.pml"
    write_goals_file(ann, goals_file)
    # each goal is searched in the configuration its annotation names (the full model is
    # too large for breadth-first search beyond a few cycles); its vector goes to that
    # configuration's file, whose header describes it
    bases = {}
    for cfg in sorted({g.config or "" for g in ann.goals}):
        _progress(f"compiling trap model [{cfg or 'default'}]")
        bases[cfg or None] = spin_mod.prepare(model, params_dir, workdir / f"traps-{cfg or 'default'}",
                                              ["TRAPS"] + ([cfg] if cfg else []), [goals_file])

    def run_goal(g):
        defs = ["TRAPS"] + ([g.config] if g.config else [])
        return (g, *search_goal(model, bases[g.config], workdir, g, defs, parse_events))

    with ThreadPoolExecutor(max_workers=max(1, jobs)) as ex:
        outcomes = list(ex.map(run_goal, ann.goals))
    per_config = {}
    justifications = load_justifications(spec_dir, model_rel)
    vectors, coverage, problems = [], [], []
    for g, status, events, res in outcomes:
        vec_ids = []
        if status == "reached":
            kind = "boundary" if any(w in g.label.lower() for w in BOUNDARY_WORDS) else "trap"
            steps = to_steps(events, sc)
            vid = f"MB-{kind.upper()}-{g.gid}"
            per_config.setdefault(g.config, []).append(
                {"id": vid, "requirements": sorted(set(g.requirements) | observed_requirements(steps)),
                 "goal": g.gid, "kind": kind, "seed": None, "steps": steps})
            vec_ids.append(vid)
            _progress(f"{g.gid} [{g.config or 'default'}] reached in {len(steps)} steps: {g.label}")
        else:
            _progress(f"{g.gid} UNREACHABLE ({res['states_stored']} states searched): {g.label}")
        just = justifications.get(g.gid)
        if status == "unreachable" and not just:
            problems.append(f"goal {g.gid} ({g.label}) is unreachable and has no justification in "
                            f"spec/justifications/ (model {model_rel})")
        coverage.append({"id": g.gid, "label": g.label, "requirements": g.requirements, "status": status,
                         "configuration": g.config or "default",
                         "vectors": vec_ids, "justification": just if status == "unreachable" else None,
                         "states_searched": res["states_stored"] if status == "unreachable" else None})
    for gid in sorted(set(justifications) - {c["id"] for c in coverage if c["status"] == "unreachable"}):
        problems.append(f"justification {justifications[gid]} names goal {gid}, which is reached or unknown")

    sim_dir = next(iter(bases.values()))

    def walk(job):
        seed, config = job
        wd = workdir / f"walk{seed}-{config or 'default'}"
        if wd.exists():
            shutil.rmtree(wd)
        wd.mkdir()
        for f in sim_dir.glob("*.pml"):
            shutil.copy2(f, wd / f.name)
        dflags = [f"-D{config}"] if config else []
        r = spin_mod._run(["spin", *dflags, f"-n{seed}", f"-u{walk_steps}", model.name], wd, timeout=300)
        if r.returncode != 0:
            raise PipelineError(f"spin simulation seed {seed} [{config}] failed: {r.stderr[-1000:]}")
        events = parse_events(r.stdout)
        if not events:
            raise PipelineError(f"random walk seed {seed} [{config}] produced no events")
        return seed, config, events

    jobs_list = [(seed, None) for seed in range(1, walks + 1)]
    jobs_list += [(seed, c) for c in WALK_CONFIGS if c for seed in range(1, max(1, walks // 8) + 1)]
    _progress(f"{len(jobs_list)} random walks ({walks} in the full configuration, the rest in "
              f"{', '.join(c for c in WALK_CONFIGS if c)})")
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as ex:
        walked = list(ex.map(walk, jobs_list))
    for seed, config, events in walked:
        steps = to_steps(events, sc)
        tag = f"{config.replace('_', '')}S{seed}" if config else f"S{seed}"
        extra = {"FAIR": {"REQ-MB-018"}}.get(config, set())
        per_config.setdefault(config, []).append(
            {"id": f"MB-RANDOM-{tag}", "requirements": sorted(observed_requirements(steps) | extra),
             "goal": None, "kind": "random", "seed": seed, "steps": steps})
    vectors.extend(per_config.pop(None, []))
    vectors.sort(key=lambda v: (v["kind"] == "random", v["id"]))

    def checked(lines, name):
        return schema_checked_jsonl(
            Path(spec_dir) / "schemas" / "vectors_mb.schema.json", lines, name)

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    for old in out_dir.glob(f"{model.stem}.*.jsonl"):
        old.unlink()
    for config, vecs in sorted(per_config.items()):
        name = f"{model.stem}.{config.lower()}.jsonl"
        _atomic_write(out_dir / name, checked([header_for(model, b, config), *vecs], name))
    reached = sum(1 for c in coverage if c["status"] == "reached")
    vectors_all = vectors + [v for vs in per_config.values() for v in vs]
    cov = {"schema": "railproof/coverage/1", "model": model_rel, "goals": coverage, "reached": reached,
           "labelled": len(coverage), "unreachable_justified": sum(
               1 for c in coverage if c["status"] == "unreachable" and c["justification"]),
           "vectors": {"trap": sum(v["kind"] == "trap" for v in vectors_all),
                       "boundary": sum(v["kind"] == "boundary" for v in vectors_all),
                       "random": sum(v["kind"] == "random" for v in vectors_all)},
           "files": {f"{model.stem}{'.' + c.lower() if c else ''}.jsonl": len(v) for c, v in
                     [(None, vectors), *sorted(per_config.items())]}}
    _atomic_write(out_dir / f"{model.stem}.jsonl",
                  checked([header_for(model, b, None), *vectors], f"{model.stem}.jsonl"))
    _atomic_write(out_dir / f"{model.stem}.coverage.json", json.dumps(cov, indent=2, sort_keys=True) + "\n")
    _progress(f"goal coverage {reached}/{len(coverage)} reached, {cov['unreachable_justified']} "
              f"unreachable justified; {len(vectors_all)} vectors written")
    if problems:
        raise PipelineError(f"{model.name}: " + "; ".join(problems))
    return cov
