"""Rendering: the generated reStructuredText pages (Jinja templates of evidence/templates),
sphinx-build, and the manifest that hashes the package.

The HTML is produced by Sphinx alone; this module only writes reStructuredText, copies the
inputs verbatim and hashes what was written.
"""
from __future__ import annotations

import hashlib
import importlib
import inspect
import json
import os
import re
import shutil
import subprocess
import sys
from importlib import metadata
from pathlib import Path

from ..errors import PipelineError
from .text import fmt_value, one_line, rst_escape, sha256_file

MANIFEST_SCHEMA = "railproof/manifest/1"
# 1980-01-01T00:00:00Z: a fixed date for Sphinx's date-dependent values (the package shows
# no build date at all; this only keeps any date Sphinx computes independent of the clock).
SOURCE_DATE_EPOCH = "315532800"
# The pages rendered once each from templates/<page>.rst.jinja (besides the chapters, one
# page per vector file, per test page and per requirement).
PAGES = ["overview", "traceability", "hazards", "capabilities", "system", "model_checking", "test_generation",
         "tests", "seeded_faults", "analysis", "boundaries", "tool_versions", "manifest"]
EXCLUDED = {
    ".doctrees/": "Sphinx's pickled build environment: holds absolute paths and object "
                  "reprs, differs between build directories; deleted after the build",
    "html/.buildinfo": "Sphinx's incremental-build stamp: hash of the configuration, which "
                       "includes the absolute path of the input copies (tr_rootdir)",
    "html/schema_violations.json": "sphinx-needs' schema validation report: records the "
                                   "validation's wall-clock duration and rate (no setting turns "
                                   "this off); its findings are Sphinx warnings, which the build "
                                   "requires to be absent",
    "sphinx-output.log": "console output of sphinx-build: names absolute paths",
    "sphinx-warnings.log": "warnings of sphinx-build: names absolute paths (must be empty)",
    "**/__pycache__/": "Python byte code (not written: PYTHONDONTWRITEBYTECODE=1)",
}
OUTPUTS = ("manifest.json", "manifest.sha256", "evidence.json", "sphinx-warnings.log", "sphinx-output.log")


def log(msg: str) -> None:
    print(f"evidence: {msg}", file=sys.stderr, flush=True)


def write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", encoding="utf-8", newline="\n") as fh:
        fh.write(text)


def jinja_env(template_dir: Path):
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(template_dir)),
        undefined=jinja2.StrictUndefined, autoescape=False,
        trim_blocks=True, lstrip_blocks=True, keep_trailing_newline=True,
        extensions=["jinja2.ext.do"])
    env.filters["rst"] = rst_escape
    env.filters["line"] = one_line
    env.filters["num"] = fmt_value
    env.filters["rows"] = lambda items, *keys: [[it.get(k, "") for k in keys] for it in items]
    env.filters["underline"] = lambda text, ch="=": ch * max(len(str(text)), 3)
    return env


def render_sources(ctx, evidence_dir: Path, src_dir: Path, input_rows: list = ()) -> list:
    """Copy evidence/ (without its templates) to src_dir, the images the chapters embed,
    and write the generated pages (the manifest page lists input_rows); returns the page
    names."""
    template_dir = evidence_dir / "templates"
    if not (evidence_dir / "conf.py").is_file() or not template_dir.is_dir():
        raise PipelineError(f"{evidence_dir}: evidence sources (conf.py, templates/) not found")
    for ch in ctx.chapters:
        if not (template_dir / f"{ch['name']}.rst.jinja").is_file():
            raise PipelineError(f"{template_dir / (ch['name'] + '.rst.jinja')}: {ch['name']}: the "
                                "registered capability has no chapter template")
    shutil.copytree(evidence_dir, src_dir, ignore=shutil.ignore_patterns(
        "templates", "__pycache__", "*.pyc", "_build", "README.md"))
    for source, rel in ctx.images:
        (src_dir / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, src_dir / rel)
    env = jinja_env(template_dir)
    base = {"m": ctx, "inp": ctx.inp, "input_rows": list(input_rows),
            "excluded": [[k, v] for k, v in EXCLUDED.items()]}
    jobs = [(page, page, {}) for page in PAGES]
    jobs += [(ch["page"], ch["name"], {"ch": ch}) for ch in ctx.chapters]
    jobs += [(vf["page"], "vectors", {"vf": vf}) for vf in ctx.vector_files]
    jobs += [(g["page"], "tests_group", {"g": g}) for g in ctx.test_groups]
    jobs += [(r["page"], "requirement", {"r": r}) for r in ctx.requirements]
    for page, template, extra in jobs:
        write(src_dir / f"{page}.rst", env.get_template(f"{template}.rst.jinja").render(**base, **extra))
    write(src_dir / "replay_commands.inc", env.get_template("replay_commands.inc.jinja").render(**base))
    return [page for page, _, _ in jobs]


def copy_inputs(inp, inputs_dir: Path) -> list:
    """Verbatim copies of every input under OUT/inputs; returns [{path, sha256, bytes}]."""
    rows = []
    for f in sorted(inp.files, key=lambda x: x.rel):
        dest = inputs_dir / f.rel
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(f.source, dest)
        rows.append({"path": f"inputs/{f.rel}", "sha256": sha256_file(dest), "bytes": dest.stat().st_size})
    if inp.identity is not None:  # the configuration the package was rendered from (identity.py)
        dest = inputs_dir / "configuration.json"
        write(dest, json.dumps(inp.identity, indent=2, sort_keys=True) + "\n")
        rows.append({"path": "inputs/configuration.json", "sha256": sha256_file(dest), "bytes": dest.stat().st_size})
        rows.sort(key=lambda r: r["path"])
    return rows


def check_toolchain() -> None:
    """Fail early, in one line, when the documentation tool chain cannot work."""
    try:
        for name in ("sphinx", "sphinxcontrib.test_reports"):  # installed and importable
            importlib.import_module(name)
        import sphinx_needs.api
    except ImportError as exc:
        raise PipelineError(f"the Sphinx tool chain is not installed ({exc.name}); install "
                            "testgen/requirements.txt into the Python environment") from None
    if "schema" not in inspect.signature(sphinx_needs.api.add_extra_option).parameters:
        raise PipelineError(
            f"sphinx-needs {metadata.version('sphinx-needs')} cannot run sphinx-test-reports "
            f"{metadata.version('sphinx-test-reports')}: its add_extra_option() has no 'schema' "
            "argument (added in sphinx-needs 6.0.1); pin sphinx-needs>=6.0.1")


def run_sphinx(src_dir: Path, html_dir: Path, doctree_dir: Path, out_dir: Path) -> int:
    """sphinx-build -b html with everything that could vary between machines fixed.
    Returns the number of warnings; raises PipelineError on any error."""
    env = dict(os.environ)
    env.update({"SOURCE_DATE_EPOCH": SOURCE_DATE_EPOCH, "PYTHONHASHSEED": "0",
                "PYTHONDONTWRITEBYTECODE": "1", "TZ": "UTC", "LC_ALL": "C.UTF-8", "LANG": "C.UTF-8"})
    warn_file = out_dir / "sphinx-warnings.log"
    log_file = out_dir / "sphinx-output.log"
    cmd = [sys.executable, "-m", "sphinx", "-b", "html", "-E", "-j", "1", "-d", str(doctree_dir),
           "-w", str(warn_file), "--keep-going", str(src_dir), str(html_dir)]
    tail: list = []
    with log_file.open("w", encoding="utf-8") as out:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env,
                                text=True, encoding="utf-8", errors="replace")
        for line in proc.stdout:
            out.write(line)
            if line.strip():
                tail = (tail + [line.strip()])[-40:]
            line = line.rstrip()
            if line.startswith(("reading sources", "writing output", "build succeeded", "build finished",
                                "copying", "generating indices", "dumping")) \
                    or "ERROR" in line or "WARNING" in line:
                log(f"sphinx: {line[:200]}")
        rc = proc.wait()
    warnings = warn_file.read_text(encoding="utf-8", errors="replace") if warn_file.exists() else ""
    errors = [ln for ln in warnings.splitlines() if re.search(r"(?:^|:\s)(?:ERROR|CRITICAL|SEVERE)\b", ln)]
    if rc != 0 or errors:
        crash = [ln for ln in tail if re.search(r"error|exception", ln, re.IGNORECASE)]
        first = errors[0] if errors else (crash or tail or ["no output"])[-1]
        raise PipelineError(f"sphinx-build failed (exit {rc}, {len(errors)} error(s)): {first.strip()} "
                            f"[log: {log_file}]")
    return sum(1 for ln in warnings.splitlines() if "WARNING" in ln)


def _walk(base: Path, top: Path) -> list:
    rows = []
    for p in sorted(top.rglob("*")):
        rel = p.relative_to(base).as_posix()
        parts = rel.split("/")
        if not p.is_file() or "__pycache__" in parts or ".doctrees" in parts \
                or parts[-1].startswith(".buildinfo") or rel == "html/schema_violations.json":
            continue
        rows.append({"path": rel, "sha256": sha256_file(p), "bytes": p.stat().st_size})
    return rows


def write_manifest(out_dir: Path, input_rows: list) -> dict:
    artifacts = list(input_rows) + _walk(out_dir, out_dir / "src") + _walk(out_dir, out_dir / "html")
    artifacts.append({"path": "evidence.json", "sha256": sha256_file(out_dir / "evidence.json"),
                      "bytes": (out_dir / "evidence.json").stat().st_size})
    artifacts.sort(key=lambda a: a["path"])
    manifest = {"schema": MANIFEST_SCHEMA, "algorithm": "sha256", "artifacts": artifacts,
                "excluded": [{"path": k, "reason": v} for k, v in EXCLUDED.items()]}
    text = json.dumps(manifest, indent=2, sort_keys=True) + "\n"
    write(out_dir / "manifest.json", text)
    lines = [f"{a['sha256']}  {a['path']}" for a in artifacts]
    lines.append(f"{hashlib.sha256(text.encode()).hexdigest()}  manifest.json")
    write(out_dir / "manifest.sha256", "\n".join(lines) + "\n")
    return manifest


def _clear(out_dir: Path) -> None:
    for sub in ("inputs", "src", "html", ".doctrees"):
        if (out_dir / sub).exists():
            shutil.rmtree(out_dir / sub)
    for f in OUTPUTS:
        (out_dir / f).unlink(missing_ok=True)


def render_package(ctx, evidence_dir: Path, out_dir: Path) -> dict:
    """Inputs, sources, HTML, evidence.json and the manifest of ctx into out_dir.

    The package is built in ``<out_dir>.partial`` and moved into out_dir only when complete:
    after a failure out_dir holds no package (the partial one keeps the Sphinx logs)."""
    _clear(out_dir)
    work = out_dir.with_name(out_dir.name + ".partial")
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    input_rows = copy_inputs(ctx.inp, work / "inputs")
    pages = render_sources(ctx, evidence_dir, work / "src", input_rows)
    log(f"wrote {len(pages)} generated pages; running sphinx-build (html)")
    nwarn = run_sphinx(work / "src", work / "html", work / ".doctrees", work)
    shutil.rmtree(work / ".doctrees", ignore_errors=True)   # not part of the package
    if nwarn:
        log(f"sphinx-build reported {nwarn} warning(s): see {out_dir / 'sphinx-warnings.log'}")
    summary = {"schema": "railproof/evidence/1", "verdict": ctx.verdict, "problems": ctx.problems,
               "counts": ctx.counts}
    write(work / "evidence.json", json.dumps(summary, indent=2, sort_keys=True) + "\n")
    log("hashing the package")
    manifest = write_manifest(work, input_rows)
    out_dir.mkdir(parents=True, exist_ok=True)
    for name in ("inputs", "src", "html") + OUTPUTS:
        if (work / name).exists():
            (work / name).replace(out_dir / name)
    work.rmdir()
    log(f"wrote {out_dir / 'manifest.json'} ({len(manifest['artifacts'])} artifacts); verdict {ctx.verdict}")
    return {"manifest": manifest, "summary": summary, "warnings": nwarn}
