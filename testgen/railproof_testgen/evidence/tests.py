"""The test suite's results: the ctest entries of the build's one run, the detail files
rendered as test needs (sphinx-test-reports, or this module's own parse where it cannot
address a test exactly), each vector's conformance result, and every registered seeded
fault with its killers.

Fails the package: a ctest entry that did not pass, a detail file an entry should have
written and did not, a failed test case, a vector no conformance case replays (or whose
case was skipped), a case replaying a vector that is in no vector file, and a registered
seeded fault without its run or without a killer (a test that failed against it) for each
way the registry says it is killed.
"""
from __future__ import annotations

import json
import re

from .junit import ENTRY_KINDS, KIND_TITLES
from .text import display_text, plain_option

_RESULT_RANK = {"passed": 0, "skipped": 1, "failure": 2, "error": 3}
_CASE_SPLIT = re.compile(r"^(?P<name>[^\[]+)(?:$|\[(?P<param>.*)\]$)", re.DOTALL)
# how a registered fault is killed -> the ctest entry (and detail file) of that run
KILL_RUNS = {"vectors": "conformance", "unit": "unit"}
NOTE = "Rendered from the JUnit XML by the evidence build, not by sphinx-test-reports: {}."


def _counts() -> dict:
    return dict.fromkeys(_RESULT_RANK, 0)


def own_need(kind: str, title: str, fields: dict, note: str, links=(), verifies=(),
             replays=(), exact=(), blocks=(), style=None) -> str:
    """The JSON content of an ``rp-test-need`` directive (evidence/_ext): a need of
    sphinx-test-reports' type ``kind`` built from this module's parse of the XML. JSON with
    ensure_ascii has no character that could end or re-indent a reStructuredText line, so
    any test name passes through unchanged."""
    obj = {"type": kind, "title": title, "fields": fields, "note": note,
           "links": list(links), "verifies": list(verifies), "replays": list(replays),
           "exact": [list(e) for e in exact], "blocks": [list(b) for b in blocks if b[1].strip()],
           "style": style}
    return json.dumps(obj, ensure_ascii=True, sort_keys=True, indent=1)


def _time_text(t: str) -> str:
    try:
        return str(float(t)) if t else "0.0"
    except ValueError:
        return display_text(t)


def _file_why(jf) -> str:
    if jf.reports_view is None:
        return jf.reports_error
    if not plain_option(jf.rel):
        return "its path cannot be passed unchanged to sphinx-test-reports as a one-line directive option"
    return ""


def suite_why(jf, s, file_why: str) -> str:
    """Why sphinx-test-reports cannot render this suite's need exactly ("" if it can):
    its test-suite directive takes the first top-level suite of that name, and its
    test-case directive searches that suite's cases."""
    if file_why:
        return file_why
    if s.nested:
        return "a nested suite (sphinx-test-reports 1.3.1 looks suites up at the top level only)"
    if not plain_option(s.name):
        return "its suite name cannot be passed unchanged to sphinx-test-reports as a one-line directive option"
    view = jf.reports_view or []
    first = next((j for j, v in enumerate(view) if v.get("name") == s.name), None)
    if first != s.top_index:
        return "an earlier top-level suite of the file has the same name"
    theirs = [(c.get("classname"), c.get("name")) for c in view[first].get("testcases", [])]
    if theirs != [(c.classname, c.name) for c in s.cases]:
        return "sphinx-test-reports reads a different list of cases for this suite"
    return ""


def case_why(s_why: str, vcases: list, c) -> str:
    """Why sphinx-test-reports cannot render this case exactly ("" if it can)."""
    if s_why:
        return s_why
    if not (plain_option(c.name) and plain_option(c.classname)):
        return "its name cannot be passed unchanged to sphinx-test-reports as a one-line directive option"
    first = next((j for j, v in enumerate(vcases)
                  if v.get("name") == c.name and v.get("classname") == c.classname), None)
    if first != c.index:
        return ("an earlier case of the suite has the same class and name (sphinx-test-reports "
                "would show that one)")
    theirs = vcases[c.index]
    if theirs.get("result") != c.result:
        return (f"sphinx-test-reports 1.3.1 would show it as {theirs.get('result')} "
                f"(it does not read a JUnit <{c.result}> element)")
    for key in ("text", "message", "system-out"):
        t = theirs.get(key)
        if t and not t.strip():
            return f"its {key} is blank (sphinx-test-reports would emit an empty literal block)"
    return ""


_KIND_ORDER = {k: i for i, (k, _, _, _) in enumerate(ENTRY_KINDS)}


def _group(entry) -> dict:
    """The test page that shows an entry's detail file (one per test set for unit tests)."""
    key, title = entry.kind, KIND_TITLES[entry.kind]
    if entry.kind == "unit":
        key, title = f"unit_{entry.groups['set']}", f"Unit tests: test set {entry.groups['set']}"
    return {"key": key, "title": title, "page": f"tests_{key}", "order": _KIND_ORDER[entry.kind],
            "files": []}


def collect(ctx) -> None:
    run = ctx.inp.tests
    ctx.unit_links = [(str(u["test"]), str(u.get("file") or ""), rid)
                      for rid, r in sorted(ctx.trace_by_id.items())
                      for u in (r.get("links") or {}).get("unit") or []
                      if isinstance(u, dict) and u.get("test")]
    ctx.case_by_test = {}          # test name as trace.json spells it -> need id
    ctx.replays_by_vector = {}     # vector need id -> [(case need id, result)]
    ctx.test_files = []
    ctx.test_groups = []
    ctx.own_rendered = 0
    ctx.test_totals = _counts()
    ctx.unit_cases = {}            # "Suite.Test" -> [(test set, case need id)]
    ctx.fault_by_id = {f["id"]: f for c in ctx.inp.fault_owners for f in c["faults"]}
    ctx.entries = []
    groups: dict = {}
    for e in run.entries:
        jf = run.details.get(e.detail) if e.detail else None
        link = _entry_detail(ctx, e, jf, groups)
        ctx.entries.append({"name": e.name, "kind": e.kind, "result": e.result, "detail": e.detail or "",
                            "present": jf is not None, "need": link, "output": e.output})
    ctx.test_groups = sorted(groups.values(), key=lambda g: (g["order"], g["key"]))
    ctx.entry_kinds = [{"kind": k, "title": t, "entries": [e for e in ctx.entries if e["kind"] == k]}
                       for k, t, _, _ in ENTRY_KINDS]
    ctx.entry_totals = {r: sum(e["result"] == r for e in ctx.entries) for r in _RESULT_RANK}
    ctx.ignored_results = list(run.ignored)
    _conformance(ctx)
    _faults(ctx)


def _entry_detail(ctx, e, jf, groups: dict) -> str:
    """Checks one ctest entry, renders its detail file (seeded-fault runs excepted: their
    failures are the point and are shown as the fault's killers); returns the need id the
    entry links to ("" if none)."""
    if e.result != "passed":
        ctx.problem(f"ctest entry {e.name}: {'not run' if e.result == 'skipped' else e.result}")
    if e.detail and jf is None:
        ctx.problem(f"results/{e.detail}: missing result file of ctest entry {e.name}")
    if e.kind == "fault":
        if e.groups["fault"] not in ctx.fault_by_id:
            ctx.problem(f"ctest entry {e.name}: seeded fault {e.groups['fault']} is not in the registry")
            return ""
        return e.groups["fault"]
    if jf is None:
        return ""
    g = _group(e)
    group = groups.setdefault(g["key"], g)
    item = _test_file(ctx, jf, conformance=e.kind == "conformance", set_=e.groups.get("set"))
    group["files"].append(item)
    ctx.test_files.append(item)
    if e.kind == "unit" and len(jf.cases) == 1:
        return item["suites"][0]["cases"][0]["id"]
    return item["id"]


def _test_file(ctx, jf, conformance: bool, set_: str | None) -> dict:
    fid = ctx.readable("TF", jf.rel.removeprefix("tests/").removesuffix(".xml"))
    file_why = _file_why(jf)
    counts = _counts()
    suites = []
    for s in jf.suites:
        sid = ctx.readable("TS", s.name)
        s_why = suite_why(jf, s, file_why)
        vcases = [] if s_why else (jf.reports_view or [])[s.top_index].get("testcases", [])
        scounts = _counts()
        items = [_case(ctx, jf, s, c, sid, s_why, vcases, conformance, set_) for c in s.cases]
        for it in items:
            counts[it["result"]] += 1
            scounts[it["result"]] += 1
        sitem = {"id": sid, "name": s.name, "title": display_text(s.name), "cases": items,
                 "nested": s.nested, "own": ""}
        if s_why:
            sitem["own"] = own_need(
                "testsuite", display_text(s.name),
                {"file": display_text(jf.rel), "suite": display_text(s.name), "cases": len(items),
                 "passed": scounts["passed"], "skipped": scounts["skipped"],
                 "failed": scounts["failure"], "errors": scounts["error"]},
                NOTE.format(s_why), links=[fid],
                exact=[("suite", s.name)] if display_text(s.name) != s.name else [])
        suites.append(sitem)
    for k in counts:
        ctx.test_totals[k] += counts[k]
    ncases = sum(len(s["cases"]) for s in suites)
    fitem = {"id": fid, "rel": jf.rel, "suites": suites, "counts": counts, "cases": ncases,
             "error_elements": jf.error_elements, "own": "", "conformance": conformance}
    if file_why:
        fitem["own"] = own_need(
            "testfile", display_text(jf.rel),
            {"file": display_text(jf.rel), "suites": len(suites), "cases": ncases,
             "passed": counts["passed"], "skipped": counts["skipped"],
             "failed": counts["failure"], "errors": counts["error"]},
            NOTE.format(file_why))
    return fitem


def _replayed(ctx, c, title: str, rel: str) -> list:
    """The vector need a conformance case replays: its ``vector_id`` property, written by
    the conformance runner ([] for a case that replays no vector, such as the vector-set
    check)."""
    vid = c.properties.get("vector_id")
    if vid is None:
        return []
    nid = ctx.vector_by_id.get(vid)
    if nid is None:
        ctx.problem(f"test {title} ({rel}) replays vector {vid}, which is not in the vector files")
        return []
    return [nid]


def _case(ctx, jf, s, c, sid: str, s_why: str, vcases: list, conformance: bool, set_) -> dict:
    cid = ctx.readable("TC", c.classname, c.name)
    title = display_text(f"{c.classname}.{c.name}")
    reqs = sorted({rid for test, file, rid in ctx.unit_links if c.matches(test, file)})
    vecs = _replayed(ctx, c, title, jf.rel) if conformance else []
    if c.failed:
        ctx.problem(f"test {title} ({jf.rel}): {c.result}")
    for v in vecs:
        ctx.replays_by_vector.setdefault(v, []).append((cid, c.result))
    for k in c.keys() | {c.name}:
        ctx.case_by_test.setdefault(k, cid)
    if set_:
        ctx.unit_cases.setdefault(f"{c.classname}.{c.name}", []).append((set_, cid))
    item = {"id": cid, "suite": s.name, "classname": c.classname, "name": c.name, "title": title,
            "result": c.result, "verifies": reqs, "vectors": vecs, "own": ""}
    why = case_why(s_why, vcases, c)
    if why:
        ctx.own_rendered += 1
        m = _CASE_SPLIT.match(c.name)
        exact = [(k, v) for k, v in (("name", c.name), ("classname", c.classname), ("suite", s.name))
                 if display_text(v) != v]
        item["own"] = own_need(
            "testcase", title,
            {"file": display_text(jf.rel), "suite": display_text(s.name), "case": display_text(c.name),
             "case_name": display_text(m.group("name") if m else c.name),
             "case_parameter": display_text(m.group("param")) if m and m.group("param") else "",
             "classname": display_text(c.classname), "result": c.result, "time": _time_text(c.time)},
            NOTE.format(why), links=[sid], verifies=reqs, replays=vecs, exact=exact,
            blocks=[("Message", c.message), ("Text", c.text), ("System-out", c.system_out)],
            style=f"tr_{c.result}")
    return item


def _conformance(ctx) -> None:
    """Each vector's replay result: the worst result of the conformance cases replaying it."""
    stats = {"vectors": 0, "passed": 0, "failed": 0, "skipped": 0, "not_replayed": 0}
    missing, skipped = [], []
    for nid, item in ctx.vector_items.items():
        rs = ctx.replays_by_vector.get(nid, [])
        item["cases"] = [cid for cid, _ in rs]
        stats["vectors"] += 1
        if not rs:
            item["conformance"] = "not replayed"
            stats["not_replayed"] += 1
            missing.append(item["orig"])
            continue
        worst = max((r for _, r in rs), key=lambda r: _RESULT_RANK.get(r, 3))
        item["conformance"] = worst
        key = {"passed": "passed", "skipped": "skipped"}.get(worst, "failed")
        stats[key] += 1
        if worst == "skipped":
            skipped.append(item["orig"])
    ctx.conformance = stats
    if missing:
        ctx.problem(f"{len(missing)} vector(s) not replayed by any conformance test case "
                    f"(first: {missing[0]})")
    if skipped:
        ctx.problem(f"{len(skipped)} vector(s) whose conformance test case was skipped "
                    f"(first: {skipped[0]})")


def _killers(ctx, cap: str, via: str, jf) -> list:
    """The needs (or names) of the tests that failed in a run with a fault active: the vector
    a conformance case replays, the unit test case of the normal run (of the capability's
    own test set when two sets hold a test of the same name)."""
    out = []
    for c in jf.cases:
        if not c.failed:
            continue
        if via == "conformance":
            vid = c.properties.get("vector_id")
            nid = ctx.vector_by_id.get(vid) if vid else None
            out.append({"name": vid or f"{c.classname}.{c.name}", "need": nid or ""})
            continue
        name = f"{c.classname}.{c.name}"
        cands = ctx.unit_cases.get(name, [])
        nid = next((cid for s, cid in cands if s == cap), cands[0][1] if cands else "")
        out.append({"name": name, "need": nid})
    return out


def _faults(ctx) -> None:
    run = ctx.inp.tests
    entries = {e.name: e for e in run.entries}
    ctx.faults = []
    for cap in ctx.inp.fault_owners:
        for f in cap["faults"]:
            fid = ctx.claim(f["id"], "seeded fault")
            kills, reasons = [], []
            for how in f["killed_by"]:
                via = KILL_RUNS[how]
                entry = entries.get(f"{via}_fault_{f['id']}")
                jf = run.details.get(entry.detail) if entry else None
                killers = _killers(ctx, cap["name"], via, jf) if jf else []
                if entry is None:
                    reasons.append(f"no ctest entry {via}_fault_{f['id']} in this run")
                elif jf is None:
                    reasons.append(f"no result file results/{entry.detail}")
                elif jf is not None and not killers:
                    reasons.append(f"no {'vector' if how == 'vectors' else 'unit test'} failed against it")
                kills.append({"how": how, "entry": entry.name if entry else "",
                              "file": entry.detail if entry else "", "killers": killers,
                              "needs": sorted({k["need"] for k in killers if k["need"]})})
            for r in reasons:
                ctx.problem(f"seeded fault {f['id']} ({cap['name']}): {r}")
            ctx.faults.append({"id": fid, "capability": cap["name"], "text": str(f.get("text") or ""),
                               "killed_by": list(f["killed_by"]), "kills": kills,
                               "needs": sorted({n for k in kills for n in k["needs"]}),
                               "killers": sum(len(k["killers"]) for k in kills),
                               "verdict": "killed" if not reasons else "NOT KILLED",
                               "reasons": reasons})

