"""Capability chapters, driven by the capability registry (results/registry.json).

Every registered capability gets a chapter page ``<name>.rst`` rendered from
evidence/templates/<name>.rst.jinja (which extends ``_chapter.rst.jinja``) with the data
``chapter(ctx, cap)`` gathers for it from the generic results:

- its requirements (by requirement area), its models with their runs per configuration,
  named assertions, mutants, goal coverage, vector files and conformance results;
- its unit test sets (``<cap>`` and ``<cap>_<part>``), its seeded faults with their killers;
- its studies: a study ``s`` is the result ``analysis/<s>.json`` or ``<s>/<cap>.json``
  (the proofs: ``proofs/<cap>.json``); its plots: every SVG of results/<cap>/.

A result the registry promises but the build did not write fails the package (a model
without its SPIN result, vectors or goal coverage, a capability without its conformance
run or proofs, a study without its result), as does a result of a model the registry
does not know.

A capability with content of its own adds a module ``chapters/<name>.py`` (imported by
name, never listed) with any of:

``RESULT_DIRS``   further results/ folders the chapter shows (their files become inputs)
``STUDY_FILES``   {study: glob under results/} where a study's results are not found by
                  the rule above
``CONFIGURATIONS`` {configuration: description} of the model configurations (the model's
                  own ``variants`` descriptions come from its SPIN result)
``load(inp, cap)`` reads further inputs (into ``inp.extra[name]``)
``build(ctx, chapter)`` adds the chapter's own data
"""
from __future__ import annotations

import importlib
from collections import Counter
from fnmatch import fnmatch


def module(name: str):
    """The chapter module of a capability, or None if it has no content of its own."""
    try:
        return importlib.import_module(f".{name}", __package__)
    except ModuleNotFoundError as exc:
        if exc.name == f"{__package__}.{name}":
            return None
        raise


def result_dirs(registry: list) -> list:
    """The results/ folders of every chapter: results/<cap>/ and the module's RESULT_DIRS."""
    out = []
    for cap in registry:
        for d in [cap["name"]] + list(getattr(module(cap["name"]), "RESULT_DIRS", [])):
            if d not in out:
                out.append(d)
    return out


def load(inp) -> None:
    for cap in inp.registry:
        hook = getattr(module(cap["name"]), "load", None)
        if hook:
            hook(inp, cap)


def collect(ctx) -> None:
    ctx.images = []          # [(source Path, path under the Sphinx sources)]
    ctx.chapters = [chapter(ctx, cap) for cap in ctx.inp.registry]
    ctx.chapter = {ch["name"]: ch for ch in ctx.chapters}
    registered = {m["name"] for cap in ctx.inp.registry for m in cap["models"]}
    for what, items in (("model-checking result", [(m["rel"], m["model_name"]) for m in ctx.models]),
                        ("vector file", [(v["rel"], v["model"]) for v in ctx.vector_files]),
                        ("goal coverage", [(c["rel"], c["model"]) for c in ctx.coverage])):
        for rel, model in items:
            if model not in registered:
                ctx.problem(f"results/{rel}: {what} of model {model}, which the capability "
                            "registry does not list")


def _by_order(order: list):
    rank = {c: i for i, c in enumerate(order)}
    return lambda c: (rank.get(c, len(rank)), c)


def _model(ctx, cap: dict, reg_model: dict, mod) -> dict:
    """One registered model of the capability: its runs per configuration (in the registry's
    order of configurations), mutants, goal coverage and vector files."""
    name = reg_model["name"]
    mo = next((m for m in ctx.models if m["model_name"] == name), None)
    cov = next((c for c in ctx.coverage if c["model"] == name), None)
    vfs = [vf for vf in ctx.vector_files if vf["model"] == name]
    for missing, what in ((mo is None, f"spin/{name}.json (model checking)"),
                          (cov is None, f"vectors/{name}.coverage.json (goal coverage)"),
                          (not vfs, f"vectors/{name}*.jsonl (vectors)")):
        if missing:
            ctx.problem(f"results/{what}: not written for model {name} of capability {cap['name']}")
    order = _by_order(list(reg_model["configurations"]))
    runs, names, seen = [], [], []
    if mo:
        names = list(dict.fromkeys(p["name"] for p in mo["properties"]))
        rank = {n: i for i, n in enumerate(names)}
        runs = sorted(mo["properties"], key=lambda p: (rank[p["name"]], order(p["configuration"] or "default")))
        seen = [p["configuration"] or "default" for p in runs] + [mu["configuration"] for mu in mo["mutants"]]
    configs = sorted(set(reg_model["configurations"]) | set(seen), key=order)
    texts = dict(getattr(mod, "CONFIGURATIONS", {}), **(mo["variants"] if mo else {}))
    per_cfg = Counter(p["configuration"] or "default" for p in runs)
    goal_cfg: dict = {}
    for g in cov["goals"] if cov else []:
        st = goal_cfg.setdefault(g["configuration"], Counter())
        st["labelled"] += 1
        st[g["status"]] += 1
    files = [{"vf": vf, "listed": (cov or {}).get("files", {}).get(vf["name"], "n/a"),
              "kinds": ", ".join(f"{k} {n}" for k, n in sorted(Counter(it["kind"] or "(none)"
                                                                      for it in vf["items"]).items())),
              "passed": sum(it["conformance"] == "passed" for it in vf["items"]),
              "failed": sum(it["conformance"] in ("failure", "error") for it in vf["items"]),
              "not_replayed": sum(it["conformance"] in ("not replayed", "skipped") for it in vf["items"])}
             for vf in vfs]
    totals = {k: sum(f[k] for f in files) for k in ("passed", "failed", "not_replayed")}
    totals.update(count=sum(vf["count"] for vf in vfs), steps=sum(vf["steps"] for vf in vfs))
    return {"name": name, "path": f"models/{name}.pml", "result": mo, "runs": runs, "properties": names,
            "configurations": [(c, texts.get(c, ""), per_cfg.get(c, 0)) for c in configs],
            "described": any(texts.get(c) for c in configs),
            "mutants": mo["mutants"] if mo else [], "coverage": cov,
            "goal_configs": [(c, v["labelled"], v["reached"], v["unreachable"])
                             for c, v in sorted(goal_cfg.items(), key=lambda kv: order(kv[0]))],
            "vector_files": files, "vector_totals": totals}


def _studies(ctx, cap: dict, mod) -> dict:
    """{study: [result items]}: analysis results (analysis/<s>.json) or a result per
    capability in the study's folder (<s>/<cap>.json, the proofs), or the module's glob."""
    overrides = getattr(mod, "STUDY_FILES", {})
    found = {}
    for s in cap["studies"]:
        patterns = [overrides[s]] if s in overrides else [f"analysis/{s}.json", f"{s}/{cap['name']}.json"]
        items = [it for it in ctx.analyses + ctx.proofs if any(fnmatch(it["rel"], p) for p in patterns)]
        if not items:
            ctx.problem(f"results/{patterns[0]}: no result of study {s} of capability {cap['name']}")
        found[s] = items
    return found


def chapter(ctx, cap: dict) -> dict:
    name = cap["name"]
    mod = module(name)
    prefixes = tuple(f"REQ-{a}-" for a in cap["areas"])
    conformance = [tf for tf in ctx.test_files if tf["rel"] == f"tests/conformance/{name}.xml"]
    if cap.get("conformance") and not any(e["name"] == f"conformance_{name}" for e in ctx.entries):
        ctx.problem(f"capability {name}: no conformance run (ctest entry conformance_{name}) in this run")
    proofs = [p for p in ctx.proofs if p["rel"] == f"proofs/{name}.json"]
    if cap.get("proofs") and not proofs:
        ctx.problem(f"results/proofs/{name}.json: the registry gives capability {name} proofs, "
                    "the build wrote no result")
    plots = []
    for d in [name] + list(getattr(mod, "RESULT_DIRS", [])):
        for pname, path in ctx.inp.plots(d):
            src = f"plots/{d}/{pname}.svg"
            ctx.images.append((path, src))
            plots.append({"name": pname, "dir": d, "src": src, "input": f"results/{d}/{pname}.svg",
                          "scenario": None})
    ch = {"name": name, "title": cap["title"], "sources": list(cap.get("sources") or []),
          "areas": list(cap["areas"]), "design": cap["design"], "page": name,
          "parts": list(cap["runtime_parts"]),
          "requirements": [r for r in ctx.requirements if r["id"].startswith(prefixes)],
          "models": [_model(ctx, cap, m, mod) for m in cap["models"]],
          "conformance": conformance, "proofs": proofs,
          "faults": [f for f in ctx.faults if f["capability"] == name],
          "unit_sets": [g for g in ctx.test_groups if g["key"] == f"unit_{name}"
                        or g["key"].startswith(f"unit_{name}_")],
          "studies": _studies(ctx, cap, mod), "plots": plots}
    ch["analyses"] = [a for items in ch["studies"].values() for a in items if a in ctx.analyses]
    hook = getattr(mod, "build", None)
    if hook:
        hook(ctx, ch)
    return ch
