"""The context every page is rendered from, computed once from the inputs.

``Context(inputs, command)`` runs the parts in dependency order; each adds its attributes
(see the module of each part) and records every reason for a FAIL verdict with
``problem()``. Need ids are claimed here, so two inputs can never map to one need.
"""
from __future__ import annotations

import hashlib
import platform
import re
from pathlib import Path

from ..errors import PipelineError
from ..toolversions import DOC_PACKAGES, package_versions
from . import analysis, boundaries, chapters, generation, modelcheck, system, tests
from .text import fmt_value, need_id

_ASM = re.compile(r"ASM(?:-[A-Z]+)?-\d+")


class Context:
    def __init__(self, inp, command: str):
        self.inp = inp
        self.command = command
        self.need_ids: set = set()
        self.problems: list = []       # reasons for a FAIL verdict
        for note in inp.missing:
            self.problem(note)
        self._spec()
        self._trace()
        modelcheck.collect(self)
        generation.collect(self)
        tests.collect(self)
        analysis.collect(self)
        self._requirement_links()
        boundaries.collect(self)
        chapters.collect(self)
        system.collect(self)
        self._versions()
        self._verdict()

    # -- need ids and problems -----------------------------------------------------------
    def problem(self, reason: str) -> None:
        if reason not in self.problems:
            self.problems.append(reason)

    def claim(self, nid: str, what: str) -> str:
        if nid in self.need_ids:
            raise PipelineError(f"two inputs map to the same need id {nid} ({what})")
        self.need_ids.add(nid)
        return nid

    def readable(self, *parts: str, limit: int = 72) -> str:
        """A readable need id; long names keep a hash suffix, and a clash with an earlier id
        gets _2, _3 ... (inputs are processed in a fixed order)."""
        nid = need_id(*parts, upper=False)
        if len(nid) > limit:
            digest = hashlib.sha256("\0".join(parts).encode()).hexdigest()[:8].upper()
            nid = nid[:limit - 9].rstrip("_-") + "_" + digest
        base, n = nid, 1
        while nid in self.need_ids:
            n += 1
            nid = f"{base}_{n}"
        self.need_ids.add(nid)
        return nid

    def readable_free(self, *parts: str) -> str | None:
        """readable(*parts) if that id is still free, else None (the caller qualifies it)."""
        return None if need_id(*parts, upper=False) in self.need_ids else self.readable(*parts)

    # -- spec -----------------------------------------------------------------------------
    def _spec(self):
        inp = self.inp
        self.hazard_ids = {h["id"] for h in inp.hazards}
        self.asm_ids = {a["id"] for a in inp.assumptions}
        self.req_ids = {r["id"] for r in inp.requirements}
        self.hazards = [{"id": self.claim(h["id"], "hazard"), "title": h.get("title", h["id"]),
                         "text": h.get("text", ""), "severity": h.get("severity", ""),
                         "source": "; ".join(map(str, h.get("source") or []))} for h in inp.hazards]
        self.assumptions = [{"id": self.claim(a["id"], "assumption"), "title": a.get("title", a["id"]),
                             "text": a.get("text", ""), "source": "; ".join(map(str, a.get("source") or []))}
                            for a in inp.assumptions]
        self.parameters = []
        for area in sorted(inp.parameters):
            d = inp.parameters[area]
            self.parameters.append({
                "area": area, "file": Path(d["file"]).name,
                "parameters": [{"id": k, "value": fmt_value(e["value"]), "unit": e.get("unit", ""),
                                "source": e.get("source", ""),
                                "requirements": ", ".join(e.get("requirements") or [])}
                               for k, e in d["parameters"].items()],
                "bounds": [{"id": k, "value": fmt_value(e["value"]), "rationale": e.get("rationale", "")}
                           for k, e in d["model_bounds"].items()]})

    # -- trace ----------------------------------------------------------------------------
    def _trace(self):
        t = self.inp.trace
        self.trace_by_id = {r["id"]: r for r in t.get("requirements", [])}
        self.trace_errors = [str(e) for e in t.get("errors") or []]
        self.trace_warnings = [str(w) for w in t.get("warnings") or []]
        self.trace_summary = [(str(k), fmt_value(v)) for k, v in (t.get("summary") or {}).items()]
        self.trace_unknown = sorted(set(self.trace_by_id) - self.req_ids)
        if self.trace_errors:
            self.problem(f"traceability check reported {len(self.trace_errors)} error(s)")
        for rid in self.trace_unknown:
            self.problem(f"trace.json names {rid}, which is not in the specification")

    # -- requirements with their trace ----------------------------------------------------
    def _requirement_links(self):
        self.requirements = []
        self.areas = []
        by_file: dict = {}
        all_props = [p for mo in self.models for p in mo["properties"] + mo["assertions"]]
        all_mutants = [mu for mo in self.models for mu in mo["mutants"]]
        for r in self.inp.requirements:
            item = self._requirement(r, all_props, all_mutants)
            self.requirements.append(item)
            by_file.setdefault((r["_file"], r.get("_area", "")), []).append(item)
        self.areas = [{"file": f, "area": a, "requirements": items} for (f, a), items in by_file.items()]
        self.req_ok = sum(r["status"] == "ok" for r in self.requirements)

    def _requirement(self, r: dict, all_props: list, all_mutants: list) -> dict:
        rid = self.claim(r["id"], "requirement")
        t = self.trace_by_id.get(rid)
        links = (t or {}).get("links") or {}
        status = str(t.get("status", "error")) if t else "untraced"
        problems = [str(p) for p in (t or {}).get("problems") or []]
        if not t:
            problems.append("no entry in trace.json")
        if status != "ok":
            self.problem(f"{rid}: trace status {status}")
        model = []
        for m in links.get("model") or []:
            if isinstance(m, dict):
                name = str(m.get("property", ""))
                nid = self.prop_by_name.get((m.get("model"), name)) or self.prop_by_name.get(name)
                model.append({"name": name, "verdict": str(m.get("verdict", "")), "need": nid,
                              "model": str(m.get("model", ""))})
        vecs = [str(v) for v in links.get("vectors") or []]
        unit = [{"test": str(u.get("test", "")), "file": str(u.get("file", "")),
                 "need": self.case_by_test.get(str(u.get("test", "")))}
                for u in links.get("unit") or [] if isinstance(u, dict)]
        code = [{"file": str(c.get("file", "")), "unit": str(c.get("unit", ""))}
                for c in links.get("code") or [] if isinstance(c, dict)]
        analyses = [fmt_value(a) for a in links.get("analysis") or []]
        proof = [fmt_value(p) for p in links.get("proof") or []]
        goals = [fmt_value(g) for g in links.get("goals") or []]
        src = [str(s) for s in r.get("source") or []]
        asms = sorted(set(_ASM.findall(" ".join(src + [str(r.get("text", ""))]))))
        props = [p for p in all_props if rid in p["links"]]
        prop_ids = {p["id"] for p in props}
        vitems = [it for it in self.vector_items.values() if rid in it["links"]]
        return {
            "id": rid, "title": r.get("title", rid), "text": r.get("text", ""),
            "page": f"requirements/{rid}", "area": r.get("_area", ""),
            "sil": fmt_value(r.get("sil")), "source": "; ".join(src),
            "verification": ", ".join(map(str, r.get("verification") or [])),
            "defence": r.get("defence", ""), "threat": r.get("threat", ""),
            "hazards": [h for h in r.get("hazards") or [] if h in self.hazard_ids],
            "hazards_unknown": [h for h in r.get("hazards") or [] if h not in self.hazard_ids],
            "assumptions": [a for a in asms if a in self.asm_ids],
            "status": status, "problems": problems,
            "counts": (f"model {len(model)}, goals {len(goals)}, vectors {len(vecs)}, unit {len(unit)}, "
                       f"code {len(code)}, analysis {len(analyses)}, proof {len(proof)}"),
            "model": model, "model_unresolved": [m for m in model if not m["need"]],
            "props": props, "mutants": [mu for mu in all_mutants if mu["target"] in prop_ids],
            "goals": goals, "goal_rows": self.goals_by_req.get(rid, []),
            "vectors": [{"id": v, "need": self.vector_by_id.get(v)} for v in vecs],
            "vectors_unresolved": [v for v in vecs if v not in self.vector_by_id],
            "vector_stats": {"total": len(vitems),
                             "passed": sum(it["conformance"] == "passed" for it in vitems),
                             "failed": sum(it["conformance"] in ("failure", "error") for it in vitems),
                             "skipped": sum(it["conformance"] == "skipped" for it in vitems),
                             "not_replayed": sum(it["conformance"] == "not replayed" for it in vitems)},
            "unit": unit, "unit_missing": [u for u in unit if not u["need"]],
            "code": code, "analysis": analyses, "proof": proof,
        }

    # -- tool versions --------------------------------------------------------------------
    def _versions(self):
        self.tool_versions = []

        def flat(prefix, v):
            if isinstance(v, dict):
                for k, x in v.items():
                    flat(f"{prefix}.{k}" if prefix else str(k), x)
            else:
                self.tool_versions.append((prefix, fmt_value(v)))
        if self.inp.tool_versions is not None:
            flat("", self.inp.tool_versions)
        self.identity = self._identity_rows()
        self.spin_versions = [(m["model"], m["spin_version"]) for m in self.models]
        self.doc_versions = [("Python", platform.python_version())] + list(
            package_versions(DOC_PACKAGES).items())
        gens = sorted({fmt_value(h.get("generator")) for _, h, _ in self.inp.vectors if h.get("generator")})
        self.generator_versions = [("vector generator", g) for g in gens]

    def _identity_rows(self) -> list:
        """[(what, value)] of the configuration record (inputs/configuration.json)."""
        ident = self.inp.identity
        if ident is None:
            return []
        src, srcs, b = ident["source"], ident["sources"], ident["build"]
        rows = [("commit", src["commit"] or src.get("reason", "")), ("tree", src["tree"] or "-"),
                ("commit date", src["commit_date"] or "-")]
        if src["dirty"] is not None:
            rows.append(("working tree", "as committed" if not src["dirty"] else
                         f"{src['changed_count']} tracked file(s) changed since the commit: "
                         + ", ".join(src["changed"])))
        rows.append(("source files", f"{srcs['count']} files, SHA-256 over the sorted list {srcs['sha256']}"))
        if b.get("build_dir_found"):
            rows += [("build type", b["build_type"]), ("compiler", b["compiler"]),
                     ("build-type flags", b["config_flags"])]
            rows += [(f"compile flags ({k}, {i + 1} of {len(v)})", f) for k, v in b["compile_flags"].items()
                     for i, f in enumerate(v)]
            rows += [(f"option {k}", v) for k, v in b["options"].items()]
        else:
            rows.append(("build", b.get("reason", "")))
        return rows

    # -- overall --------------------------------------------------------------------------
    def _verdict(self):
        self.verdict = "FAIL" if self.problems else "PASS"
        self.counts = {
            "capabilities": len(self.chapters),
            "requirements": len(self.requirements), "requirements_ok": self.req_ok,
            "sil4": sum(1 for r in self.requirements if r["sil"] == "4"),
            "hazards": len(self.hazards), "assumptions": len(self.assumptions),
            "models": len(self.models), "properties": sum(len(m["properties"]) for m in self.models),
            "properties_verified": sum(m["verified"] for m in self.models),
            "assertions": sum(len(m["assertions"]) for m in self.models),
            "assertions_verified": sum(m["assertions_verified"] for m in self.models),
            "mutants": sum(len(m["mutants"]) for m in self.models),
            "mutants_rejected": sum(m["rejected"] for m in self.models),
            "vector_files": len(self.vector_files),
            "vectors": sum(f["count"] for f in self.vector_files),
            "vector_steps": sum(f["steps"] for f in self.vector_files),
            "goals_labelled": sum(c["labelled"] for c in self.coverage),
            "goals_reached": sum(c["reached"] for c in self.coverage),
            "goals_unreachable": sum(len(c["unreachable"]) for c in self.coverage),
            "ctest_entries": len(self.entries),
            "ctest_passed": self.entry_totals["passed"],
            "test_files": len(self.test_files),
            "test_cases": sum(f["cases"] for f in self.test_files),
            "tests_passed": self.test_totals["passed"], "tests_failed": self.test_totals["failure"],
            "tests_errors": self.test_totals["error"], "tests_skipped": self.test_totals["skipped"],
            "tests_rendered_from_xml": self.own_rendered,
            "vectors_replayed_passed": self.conformance["passed"],
            "vectors_replay_failed": self.conformance["failed"],
            "vectors_not_replayed": self.conformance["not_replayed"] + self.conformance["skipped"],
            "seeded_faults": len(self.faults),
            "seeded_faults_killed": sum(f["verdict"] == "killed" for f in self.faults),
            "analyses": len(self.analyses),
            "analyses_pass": sum(a["outcome"] == "pass" for a in self.analyses),
            "proof_obligations": sum(len(p["rows"]) for p in self.proofs),
            "proof_obligations_ok": sum(p["ok"] for p in self.proofs),
            "build_targets": sum(len(self.layout[k]) for k in ("runtime", "offline", "tests"))
            if self.layout else 0,
        }
