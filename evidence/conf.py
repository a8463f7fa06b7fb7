"""Sphinx configuration of the railproof evidence package.

This file is copied, with the rest of evidence/, into OUT_DIR/src by
``python -m railproof_testgen evidence``; the generated pages are written beside it
and the package is rendered from there. Nothing here depends on the build
machine, the date or the output directory, so two builds of the same inputs are
byte-identical (see evidence/_ext/railproof_evidence.py for the one fix needed).
"""
import os
import sys
from pathlib import Path

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "_ext"))

project = "railproof evidence package"
author = "the railproof project"
copyright = "the railproof project"  # no year: the build date must not enter the output
version = release = ""

extensions = [
    "sphinx_needs",
    "sphinxcontrib.test_reports",
    "railproof_evidence",
]

root_doc = "index"
exclude_patterns = ["_build", "**/*.inc.rst"]
templates_path = []
html_static_path = ["_static"]
html_css_files = ["railproof.css"]
html_theme = "alabaster"
html_theme_options = {
    "page_width": "96%",
    "sidebar_width": "240px",
    "fixed_sidebar": False,
    "show_powered_by": True,
}
html_title = "railproof evidence package"
html_last_updated_fmt = None   # no build time in the pages
html_show_sourcelink = True
html_copy_source = True
highlight_language = "none"
language = "en"
today_fmt = ""                 # |today| must not carry the build date

# --- sphinx-needs ------------------------------------------------------------------------
# One need type per kind of evidence. IDs are the project's own (REQ-TG-001, HAZ-001, ...).
needs_types = [
    {"directive": "req", "title": "Requirement", "prefix": "REQ-", "color": "#BFD8D2", "style": "node"},
    {"directive": "haz", "title": "Hazard", "prefix": "HAZ-", "color": "#F4B6B6", "style": "node"},
    {"directive": "asm", "title": "Assumption", "prefix": "ASM-", "color": "#E8E2C8", "style": "node"},
    {"directive": "prop", "title": "Model property", "prefix": "PROP_", "color": "#C9D7F2", "style": "node"},
    {"directive": "mut", "title": "Mutant model", "prefix": "MUT_", "color": "#D9C9F2", "style": "node"},
    {"directive": "vec", "title": "Conformance vector", "prefix": "VEC_", "color": "#DCEFD0", "style": "node"},
    {"directive": "res", "title": "Analysis result", "prefix": "RES_", "color": "#F2E1C9", "style": "node"},
    {"directive": "fault", "title": "Seeded fault", "prefix": "FAULT_", "color": "#F2C9D9", "style": "node"},
]
needs_id_regex = r"^[A-Za-z][A-Za-z0-9_-]{2,}$"   # no dots: sphinx-needs uses ID.part
needs_id_required = True

# Option names must not clash with those sphinx-test-reports registers itself
# (file, suite, case, case_name, case_parameter, classname, time, suites, cases,
# passed, skipped, failed, errors, result).
needs_extra_options = [
    {"name": "sil", "description": "safety integrity level of a requirement"},
    {"name": "source", "description": "document sections the entry is derived from"},
    {"name": "verification", "description": "verification methods the requirement demands"},
    {"name": "defence", "description": "EN 50159 defence"},
    {"name": "threat", "description": "EN 50159 threat"},
    {"name": "evidence", "description": "counts of linked evidence per kind (from trace.json)"},
    {"name": "problems", "description": "problems the traceability check reported"},
    {"name": "severity", "description": "severity of a hazard"},
    {"name": "model", "description": "Promela model file"},
    {"name": "verdict", "description": "model-checking or mutant verdict"},
    {"name": "states", "description": "states stored by SPIN"},
    {"name": "depth", "description": "search depth reached by SPIN"},
    {"name": "spin_errors", "description": "errors SPIN reported"},
    {"name": "time_s", "description": "SPIN run time in seconds"},
    {"name": "memory_mb", "description": "SPIN memory in MiB"},
    {"name": "transitions", "description": "transitions SPIN explored"},
    {"name": "configuration", "description": "model configuration a property is checked in"},
    {"name": "property_kind", "description": "ltl (a named LTL property) or assertion (a named assert() of the model)"},
    {"name": "expect", "description": "expected verdict of a mutant"},
    {"name": "goal", "description": "test-generation goal a vector reaches"},
    {"name": "steps", "description": "number of steps of a vector"},
    {"name": "vector_file", "description": "vector file the vector belongs to"},
    {"name": "kind", "description": "how a vector was generated (trap, boundary, random)"},
    {"name": "role", "description": "endpoint a vector drives (train or ground)"},
    {"name": "conformance", "description": "result of replaying a vector against the C++ implementation"},
    {"name": "analysis", "description": "analysis result file"},
    {"name": "outcome", "description": "pass or fail of an analysis against its target"},
    {"name": "capability", "description": "capability of the registry a seeded fault belongs to"},
    {"name": "kill_runs", "description": "how the registry says a seeded fault is killed (vectors, unit)"},
    {"name": "killers", "description": "number of tests that failed with the seeded fault active"},
]

needs_extra_links = [
    {"option": "hazards", "outgoing": "addresses hazard", "incoming": "addressed by"},
    {"option": "assumptions", "outgoing": "relies on", "incoming": "relied on by"},
    {"option": "model_checks", "outgoing": "checks", "incoming": "checked by property"},
    {"option": "exercises", "outgoing": "exercises", "incoming": "exercised by vector"},
    {"option": "verifies", "outgoing": "verifies", "incoming": "verified by test"},
    {"option": "replays", "outgoing": "replays vector", "incoming": "replayed by"},
    {"option": "quantifies", "outgoing": "quantifies", "incoming": "quantified by"},
    {"option": "targets", "outgoing": "must be killed by", "incoming": "kills mutant"},
    {"option": "killed_by", "outgoing": "killed by", "incoming": "kills seeded fault"},
]

needs_table_style = "DATATABLES"
needs_default_layout = "clean"
needs_collapse_details = True
needs_show_link_type = False
needs_role_need_template = "{id}"     # :need: references show the bare id
# Machine-readable copy of every need beside the HTML; without a build timestamp.
needs_build_json = True
needs_reproducible_json = True

# --- sphinx-test-reports ------------------------------------------------------------------
# JUnit XML files are read from the verbatim input copies in OUT_DIR/inputs/results, so the
# paths shown in the pages are relative to the results directory.
tr_rootdir = Path(__file__).resolve().parent.parent / "inputs" / "results"
# Test cases name the requirements they verify (from trace.json) and the vector they replay.
tr_extra_options = ["verifies", "replays"]
