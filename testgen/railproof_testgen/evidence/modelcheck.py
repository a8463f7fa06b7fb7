"""Model checking: one entry per SPIN result file (results/spin/<model>.json) with its
properties, named assertions and mutants as needs.

A property or assertion that is not ``verified``, a mutant whose verdict is not the expected
one, a requirement id the specification does not define and a model hash that differs
from the source tree fail the package.
"""
from __future__ import annotations

from pathlib import Path

from .text import fields, fmt_value, sha256_file

_PROP_SHOWN = {"name", "requirements", "verdict", "states_stored", "depth", "errors", "time_s",
               "memory_mb", "text", "configuration", "command", "counterexample", "transitions",
               "incomplete"}
_ASSERT_SHOWN = {"name", "requirements", "verdict", "text", "runs", "basis"}
_MUT_SHOWN = {"name", "expect", "verdict", "property", "text", "counterexample", "configuration"}
_MODEL_SHOWN = {"model", "model_sha256", "spin_version", "bounds", "properties", "assertions",
                "mutants", "variants"}


def collect(ctx) -> None:
    ctx.models = []
    ctx.prop_by_name = {}       # name or (model, name) -> need id
    for rel, d in ctx.inp.spin:
        ctx.models.append(_model(ctx, rel, d))


def _source_check(ctx, model: str, sha: str) -> str:
    src = ctx.inp.repo_root / model
    if not sha:
        return "no model hash in the result"
    if not src.is_file():
        return "model file not in the source tree"
    return "matches the source tree" if sha256_file(src) == sha else "DIFFERS from the source tree"


def _reqs(ctx, what: str, reqs) -> tuple:
    """(known, unknown) requirement ids of a result entry; unknown ones fail the package."""
    reqs = [str(r) for r in reqs or []]
    unknown = [r for r in reqs if r not in ctx.req_ids]
    for r in unknown:
        ctx.problem(f"{what} names unknown requirement {r}")
    return [r for r in reqs if r in ctx.req_ids], unknown


def _model(ctx, rel: str, d: dict) -> dict:
    stem = Path(rel).stem
    model = str(d.get("model", stem))
    sha = str(d.get("model_sha256", ""))
    src_check = _source_check(ctx, model, sha)
    if src_check.startswith("DIFFERS"):
        ctx.problem(f"{model}: model hash in {rel} differs from the source tree")
    props = [_property(ctx, model, stem, p) for p in d.get("properties", [])]
    assertions = [_assertion(ctx, model, stem, a) for a in d.get("assertions", [])]
    by_name = {p["name"]: p["id"] for p in props + assertions}
    mutants = [_mutant(ctx, model, stem, m, by_name) for m in d.get("mutants", [])]
    commands = []
    for p in props:
        if p["command"] and p["command"] not in commands:
            commands.append(p["command"])
    variants = {str(v.get("define")): str(v.get("text") or "") for v in d.get("variants") or []
                if isinstance(v, dict)}
    return {"rel": rel, "stem": stem, "model": model, "model_name": Path(model).stem, "sha": sha, "src_check": src_check,
            "spin_version": str(d.get("spin_version", "n/a")),
            "bounds": [(str(k), fmt_value(v)) for k, v in (d.get("bounds") or {}).items()],
            "other": fields(d, _MODEL_SHOWN), "variants": variants,
            "properties": props, "assertions": assertions, "mutants": mutants,
            "source": ctx.inp.model_copies.get(model), "commands": commands,
            "verified": sum(p["verdict"] == "verified" for p in props),
            "assertions_verified": sum(a["verdict"] == "verified" for a in assertions),
            "rejected": sum(m["verdict"] == m["expect"] for m in mutants)}


def _own_id(ctx, prefix: str, name: str, *qualifiers: str) -> str:
    """PREFIX_<name>, or with the qualifiers appended when another model or configuration
    already holds that id."""
    first = ctx.readable_free(prefix, name)
    return first or ctx.readable(prefix, name, *[q for q in qualifiers if q])


def _property(ctx, model: str, stem: str, p: dict) -> dict:
    config = str(p.get("configuration") or "")
    nid = _own_id(ctx, "PROP", p["name"], config or stem)
    links, unknown = _reqs(ctx, f"model property {p['name']}", p.get("requirements"))
    verdict = str(p["verdict"])
    if verdict != "verified":
        where = f"{model}, configuration {config}" if config else model
        ctx.problem(f"model property {p['name']} ({where}): {verdict}")
    incomplete = p.get("incomplete") or []
    ctx.prop_by_name.setdefault(p["name"], nid)
    ctx.prop_by_name.setdefault((model, p["name"]), nid)
    return {"id": nid, "name": p["name"], "kind": "ltl", "verdict": verdict,
            "text": str(p.get("text") or ""), "configuration": config,
            "states": fmt_value(p.get("states_stored")), "transitions": fmt_value(p.get("transitions")),
            "depth": fmt_value(p.get("depth")), "errors": fmt_value(p.get("errors")),
            "time_s": fmt_value(p.get("time_s")), "memory_mb": fmt_value(p.get("memory_mb")),
            "command": str(p.get("command") or ""), "counterexample": str(p.get("counterexample") or ""),
            "incomplete": fmt_value(incomplete) if incomplete else "",
            "links": links, "unknown": unknown, "extra": fields(p, _PROP_SHOWN)}


def _assertion(ctx, model: str, stem: str, a: dict) -> dict:
    """A named model assertion (``// @assert``): pan checks it in every verification run of
    its model; the result file gives its verdict and the basis of that verdict."""
    name = str(a["name"])
    label = name.removeprefix("assert:")
    nid = _own_id(ctx, "ASSERT", label, stem)
    links, unknown = _reqs(ctx, f"model assertion {label}", a.get("requirements"))
    verdict = str(a["verdict"])
    if verdict != "verified":
        ctx.problem(f"model assertion {label} ({model}): {verdict}")
    ctx.prop_by_name.setdefault(name, nid)
    ctx.prop_by_name.setdefault((model, name), nid)
    return {"id": nid, "name": name, "label": label, "kind": "assertion", "verdict": verdict,
            "text": str(a.get("text") or ""), "basis": str(a.get("basis") or ""),
            "runs": fmt_value(a.get("runs")), "links": links, "unknown": unknown,
            "extra": fields(a, _ASSERT_SHOWN)}


def _mutant(ctx, model: str, stem: str, m: dict, by_name: dict) -> dict:
    nid = _own_id(ctx, "MUT", m["name"], stem)
    expect = str(m.get("expect", "rejected"))
    verdict = str(m["verdict"])
    if verdict != expect:
        ctx.problem(f"mutant {m['name']} ({model}): {verdict}, expected {expect}")
    prop = str(m.get("property") or "")
    return {"id": nid, "name": m["name"], "expect": expect, "verdict": verdict, "property": prop,
            "target": by_name.get(prop), "configuration": str(m.get("configuration") or "default"),
            "text": str(m.get("text") or ""), "counterexample": str(m.get("counterexample") or ""),
            "extra": fields(m, _MUT_SHOWN)}
