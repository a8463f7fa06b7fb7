"""Offline studies (results/analysis/*.json) and SMT proofs (results/proofs/<cap>.json).

One need per analysis result. Nested objects are flattened into dotted names
(``channel.loss_probability``); a list of records, or an object whose values are all records
(``checks``: one record per requirement), is a table with flattened columns. A record with
``meets_target: false``, ``result: FAIL`` or a failed ``verdict`` (at the top level or in a
table) fails the package, as does a proof obligation that does not come back with its expected verdict from
both solvers.
"""
from __future__ import annotations

from pathlib import Path

from .text import flatten, fmt_value, need_id

SOLVERS = ("z3", "cvc5")


FAILED_VERDICTS = {"fail", "failed", "violated", "error"}


def _fails(row: dict) -> bool:
    return (row.get("meets_target") is False or str(row.get("result")) == "FAIL"
            or str(row.get("verdict", "")).lower() in FAILED_VERDICTS)


def _records(v):
    """[(key or None, record)] if v is a table of records, else None."""
    if isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
        return [(None, x) for x in v]
    if isinstance(v, dict) and v and all(isinstance(x, dict) for x in v.values()):
        return list(v.items())
    return None


def _table(name: str, records: list, fails: list) -> dict:
    flat = [flatten(row) for _, row in records]
    cols = [] if records[0][0] is None else ["key"]
    for row in flat:
        cols += [c for c in row if c not in cols]
    rows = [[fmt_value(key if c == "key" and key is not None else row.get(c)) for c in cols]
            for (key, _), row in zip(records, flat)]
    fails += [f"{name}[{i if key is None else key}]"
              for i, ((key, _), row) in enumerate(zip(records, flat)) if _fails(row)]
    return {"name": name, "columns": cols, "rows": rows}


def collect(ctx) -> None:
    ctx.analyses = []
    for rel, d in ctx.inp.analysis:
        ctx.analyses.append(_analysis(ctx, rel, d))
    ctx.proofs = [_proof(ctx, rel, d) for rel, d in ctx.inp.proofs]


def _analysis(ctx, rel: str, d: dict) -> dict:
    stem = Path(rel).stem
    nid = ctx.claim(need_id("RES", stem), f"analysis {rel}")
    reqs = [str(r) for r in d.get("requirements") or []]
    scalars, tables, fails = [], [], []
    for k, v in d.items():
        if k == "requirements":
            continue
        records = _records(v)
        if records is not None:
            tables.append(_table(k, records, fails))
        elif isinstance(v, dict):
            scalars += [(fk, fmt_value(fv)) for fk, fv in flatten(v, k).items()]
        else:
            scalars.append((k, fmt_value(v) if v != [] else "none"))
            if _fails({k: v}):
                fails.append(k)
    for r in reqs:
        if r not in ctx.req_ids:
            ctx.problem(f"analysis {rel} names unknown requirement {r}")
    if fails:
        ctx.problem(f"analysis {rel}: target not met in {', '.join(fails)}")
    return {"id": nid, "rel": rel, "stem": stem, "title": stem.replace("_", " "),
            "schema": str(d.get("schema") or ""), "links": [r for r in reqs if r in ctx.req_ids],
            "unknown": [r for r in reqs if r not in ctx.req_ids], "scalars": scalars,
            "tables": tables, "outcome": "fail" if fails else "pass", "fails": fails, "data": d}


def _obligation(ctx, rel: str, ob: dict) -> dict:
    res = {}
    for solver in SOLVERS:
        r = ob.get(solver) if isinstance(ob.get(solver), dict) else {}
        res[solver] = (str(r.get("verdict", "n/a")), fmt_value(r.get("time_s")))
    expected = str(ob.get("expected", "n/a"))
    ok = ob.get("meets_target") is not False and all(v == expected for v, _ in res.values())
    if not ok:
        ctx.problem(f"proof {rel}: obligation {ob.get('name')} did not come back {expected} "
                    "from both solvers")
    reqs = [str(r) for r in ob.get("requirements") or []]
    return {"name": str(ob.get("name", "?")), "requirements": reqs,
            "links": [r for r in reqs if r in ctx.req_ids], "expected": expected,
            "z3": res["z3"], "cvc5": res["cvc5"], "ok": ok,
            "text": str(ob.get("text") or ob.get("title") or ""), "file": str(ob.get("smt2") or ""),
            "source": str(ob.get("source") or ""),
            "counterexample": {
                solver: ", ".join(f"{k} = {v}" for k, v in sorted(ob[solver]["model"].items()))
                for solver in SOLVERS
                if isinstance(ob.get(solver), dict) and isinstance(ob[solver].get("model"), dict)}}


def _proof(ctx, rel: str, d: dict) -> dict:
    rows = [_obligation(ctx, rel, ob) for ob in d.get("obligations") or [] if isinstance(ob, dict)]
    if str(d.get("verdict", "pass")).lower() not in ("pass", "passed", "ok"):
        ctx.problem(f"proof {rel}: verdict {d.get('verdict')!r}")
    solvers = d.get("solvers") if isinstance(d.get("solvers"), dict) else {}
    return {"rel": rel, "capability": str(d.get("capability") or Path(rel).stem), "rows": rows,
            "verdict": str(d.get("verdict", "n/a")), "command": str(d.get("command") or ""),
            "ok": sum(r["ok"] for r in rows),
            "solvers": [(k, fmt_value(v.get("version") if isinstance(v, dict) else v))
                        for k, v in sorted(solvers.items())]}
