"""Local Sphinx extension of the evidence package: reproducible need container ids.

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

from docutils import nodes

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


def setup(app):
    app.connect("doctree-resolved", _stable_container_ids, priority=900)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
