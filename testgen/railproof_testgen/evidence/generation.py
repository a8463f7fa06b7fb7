"""Test generation: the vector files (one need per vector, one page per file) and the goal
coverage of each model.

A reached goal without a vector, an unreachable goal without a justification, a goal naming
a vector that is in no vector file, a vector naming an unknown requirement and a vector set
without vectors fail the package.
"""
from __future__ import annotations

import re
from collections import Counter
from pathlib import Path

from .text import fmt_value, need_id, safe_json_line

_VECTOR_SHOWN = ("id", "requirements", "goal", "steps", "kind", "role")


def model_of_file(name: str) -> str:
    """The model a vector or coverage file belongs to: ``mb`` for mb.jsonl, mb.core.jsonl
    and mb.coverage.json."""
    return re.sub(r"\.(?:jsonl|coverage\.json)$", "", name).split(".")[0]


def collect(ctx) -> None:
    ctx.vector_files = []
    ctx.vector_by_id = {}       # vector id -> need id
    ctx.vector_items = {}       # need id -> item
    for rel, header, vectors in ctx.inp.vectors:
        ctx.vector_files.append(_vector_file(ctx, rel, header, vectors))
    if ctx.inp.vectors and not any(f["count"] for f in ctx.vector_files):
        ctx.problem("the vector files hold no vectors")
    ctx.coverage = []
    ctx.goals_by_req = {}
    for rel, d in ctx.inp.coverage:
        ctx.coverage.append(_coverage(ctx, rel, d))


def _title(v: dict) -> str:
    if v.get("goal"):
        return str(v["goal"])
    if v.get("seed") is not None:
        return f"{v.get('kind') or 'random'} walk, seed {fmt_value(v['seed'])}"
    return str(v["id"])


def _vector_file(ctx, rel: str, header: dict, vectors: list) -> dict:
    name = Path(rel).name
    stem = name[:-len(".jsonl")]
    by_req: dict = {}
    items = []
    for v in vectors:
        nid = ctx.claim(need_id(v["id"], upper=False), f"vector {v['id']}")
        reqs = [str(r) for r in v.get("requirements") or []]
        steps = v.get("steps") or []
        item = {"id": nid, "orig": v["id"], "goal": str(v.get("goal") or ""), "title": _title(v),
                "kind": str(v.get("kind") or ""), "role": str(v.get("role") or ""),
                "links": [r for r in reqs if r in ctx.req_ids],
                "unknown": [r for r in reqs if r not in ctx.req_ids],
                "nsteps": len(steps), "steps": [safe_json_line(s) for s in steps],
                "conformance": "not replayed", "cases": [],
                "extra": sorted((k, fmt_value(x)) for k, x in v.items() if k not in _VECTOR_SHOWN)}
        items.append(item)
        ctx.vector_by_id[v["id"]] = nid
        ctx.vector_items[nid] = item
        by_req.setdefault(reqs[0] if reqs else "(no requirement)", []).append(item)
        for r in item["unknown"]:
            ctx.problem(f"vector {v['id']} names unknown requirement {r}")
    per_req = Counter(r for it in items for r in it["links"] + it["unknown"])
    return {"rel": rel, "name": name, "stem": stem, "model": model_of_file(name),
            "page": "vectors_" + re.sub(r"[^A-Za-z0-9_]+", "_", stem),
            "configuration": str(header.get("configuration") or "default"),
            "header": [(k, fmt_value(x)) for k, x in header.items()
                       if k not in ("kind", "parameters", "unit_scales")],
            "unit_scales": [(k, fmt_value(x)) for k, x in (header.get("unit_scales") or {}).items()],
            "parameters": [(k, fmt_value(x)) for k, x in (header.get("parameters") or {}).items()],
            "items": items, "count": len(items), "steps": sum(i["nsteps"] for i in items),
            "groups": [(r, by_req[r]) for r in sorted(by_req)], "per_req": sorted(per_req.items())}


def _goal_vectors(g: dict) -> list:
    vecs = g.get("vectors")
    if vecs is None:          # one "vector" per goal (spec/design/tg.md §8)
        vecs = [g["vector"]] if g.get("vector") else []
    elif not isinstance(vecs, list):
        vecs = [vecs]
    return [str(v) for v in vecs if v]


def _coverage(ctx, rel: str, d: dict) -> dict:
    goals = []
    for g in d["goals"]:
        status = str(g["status"])
        vecs = _goal_vectors(g)
        just = g.get("justification")
        if not ((status == "reached" and vecs) or (status == "unreachable" and just)):
            ctx.problem(f"goal {g['id']} ({rel}): {status} without "
                        f"{'vector' if status == 'reached' else 'justification'}")
        for v in vecs:
            if v not in ctx.vector_by_id:
                ctx.problem(f"goal {g['id']} ({rel}) names vector {v}, which is not in the vector files")
        jentry = ctx.inp.justifications.get(str(just)) if just else None
        reqs = [str(r) for r in g.get("requirements") or []]
        goal = {"id": str(g["id"]), "label": str(g.get("label", "")), "requirements": ", ".join(reqs),
                "reqs": reqs, "status": status, "vectors": vecs,
                "configuration": str(g.get("configuration") or "default"),
                "vector_needs": [ctx.vector_by_id[v] for v in vecs if v in ctx.vector_by_id],
                "justification": str(just) if just else "",
                "justification_text": " ".join(str(jentry.get("text", "")).split()) if jentry else "",
                "states_searched": fmt_value(g["states_searched"])
                if g.get("states_searched") is not None else "",
                "rel": rel}
        goals.append(goal)
        if goal["label"]:
            for nid in goal["vector_needs"]:
                ctx.vector_items[nid]["title"] = f"{goal['id']}: {goal['label']}"
        for r in reqs:
            ctx.goals_by_req.setdefault(r, []).append(goal)
    files = d.get("files") if isinstance(d.get("files"), dict) else {}
    return {"rel": rel, "model": model_of_file(Path(rel).name), "goals": goals,
            "reached": d.get("reached", sum(g["status"] == "reached" for g in goals)),
            "labelled": d.get("labelled", len(goals)),
            "unreachable": [g for g in goals if g["status"] == "unreachable"],
            "files": {str(k): fmt_value(v) for k, v in files.items()},
            "extra": [(k, fmt_value(v)) for k, v in d.items()
                      if k not in ("goals", "reached", "labelled", "files")]}
