"""Local Sphinx extension of the evidence package.

1. ``rp-test-need``: a test file, suite or case need that sphinx-test-reports cannot
   render exactly, built from the evidence build's own parse of the JUnit XML.
2. Reproducible need container ids.

rp-test-need
------------

sphinx-test-reports 1.3.1 finds a test case by the ``:case:`` and ``:classname:`` options
of its ``test-case`` directive, which hold one line of text. A pytest parametrised name
can hold newlines, leading blanks or ``[[`` (which sphinx-needs would read as a dynamic
function); two cases can share a name; a JUnit ``<error>`` is shown as passed; and its
parser stops on a non-numeric ``time``. For those items the evidence build writes

.. code-block:: rst

   .. rp-test-need:: TC_some_id

      {"type": "testcase", "title": ..., "fields": {...}, "links": [...], ...}

with the item as JSON (ASCII only, so no character of a test name can end or re-indent a
line). The directive creates the need through ``sphinx_needs.api.add_need`` with the need
type and options sphinx-test-reports registers (``testcase``: file, suite, case,
case_name, case_parameter, classname, result, time), so need tables and filters treat
both kinds alike. The exact name is shown in a literal block when its one-line form
differs; failure message, text and system-out likewise.

Container ids
-------------

sphinx-needs 6.0.0 gives the ``<div>`` around every rendered need an id made from
``uuid.uuid4()`` (``sphinx_needs/layout.py``: ``"SNCB-" + str(uuid.uuid4())[:8]``;
upstream issue useblocks/sphinx-needs#1903, open, no configuration switch), so two
builds of the same sources differ in those ids. Its only consumer is the collapse
script of sphinx-needs, which needs an id that starts with ``SNCB-`` and is unique
within the page.

This handler runs on ``doctree-resolved`` after sphinx-needs has rendered the needs
(priority 900 > the default 500) and replaces each such id in the doctree, before
any HTML is written, by ``SNCB-`` + the first 8 hex digits of SHA-256 over the
document name, the need id and its occurrence on the page. Nothing is changed
after writing; the ids depend only on the sources.
"""
from __future__ import annotations

import hashlib
import json

from docutils import nodes
from sphinx.util.docutils import SphinxDirective

_PREFIX = "SNCB-"


def _need_id(container: nodes.Element) -> str:
    # The need's own id is carried by the first element below the container that
    # has ids (the need table / its target); fall back to the need's CSS classes.
    for sub in container.findall(nodes.Element):
        if sub is container:
            continue
        for ident in sub.get("ids", []):
            if not ident.startswith(_PREFIX):
                return ident
    return ""


def _stable_container_ids(app, doctree: nodes.document, docname: str) -> None:
    seen: dict[str, int] = {}
    used: set[str] = set()
    for container in doctree.findall(nodes.container):
        if "need_container" not in container.get("classes", []):
            continue
        ids = container.get("ids", [])
        if not ids or not ids[0].startswith(_PREFIX):
            continue
        key = _need_id(container)
        n = seen.get(key, 0)
        seen[key] = n + 1
        salt = 0
        while True:
            digest = hashlib.sha256(f"{docname}\0{key}\0{n}\0{salt}".encode()).hexdigest()[:8]
            new_id = _PREFIX + digest
            if new_id not in used:
                break
            salt += 1
        used.add(new_id)
        container["ids"] = [new_id] + ids[1:]


def _literal(label: str, text: str) -> list[str]:
    """A paragraph ``label:`` followed by text as a literal block (never parsed)."""
    lines = [ln.rstrip() for ln in text.splitlines()]
    while lines and not lines[-1]:
        lines.pop()
    while lines and not lines[0]:
        lines.pop(0)
    if not lines:
        return []
    return [label + "::", ""] + ["   " + ln if ln else "" for ln in lines] + [""]


class TestNeedDirective(SphinxDirective):
    """``.. rp-test-need:: <need id>`` with the item as JSON content (see the module doc)."""

    required_arguments = 1
    has_content = True

    def run(self):
        from sphinx_needs.api import add_need
        from sphinx_needs.utils import add_doc

        data = json.loads("\n".join(self.content))
        cfg = self.config
        need_type = {"testfile": cfg.tr_file[1], "testsuite": cfg.tr_suite[1],
                     "testcase": cfg.tr_case[1]}[data["type"]]
        rst: list[str] = []
        if data.get("note"):
            rst += [data["note"], ""]
        for key, value in data.get("exact") or []:
            rst += _literal(f"Exact {key} in the XML, as a JSON string", json.dumps(value))
        for label, text in data.get("blocks") or []:
            rst += _literal(f"**{label}**", text)
        kwargs = dict(data.get("fields") or {})
        for option in ("links", "verifies", "replays"):
            if data.get(option):
                kwargs[option] = list(data[option])
        result = add_need(self.env.app, self.state, self.env.docname, self.lineno,
                          need_type=need_type, title=data["title"], id=self.arguments[0],
                          content="\n".join(rst), collapse=bool(data.get("collapse", True)),
                          style=data.get("style"), **kwargs)
        add_doc(self.env, self.env.docname)
        return result


def setup(app):
    app.add_directive("rp-test-need", TestNeedDirective)
    app.connect("doctree-resolved", _stable_container_ids, priority=900)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
