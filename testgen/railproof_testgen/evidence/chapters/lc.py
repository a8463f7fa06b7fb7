"""The level-crossing chapter's own content: the peer cross-check of its design note
(spec/design/lc.md §7), one row per failure mode of the classic radio-based level-crossing
case study with the railproof property, requirement or assumption that covers it. Every
identifier a row names must exist, or the package fails.
"""
from __future__ import annotations

import re

from ..inputs import load_markdown_table

PEER_CHECK = ("design/lc.md", r"^## 7\. Peer cross-check")
ID_TOKEN = re.compile(r"\b(?:REQ|HAZ|ASM)-[A-Z0-9]+(?:-[0-9]+)?\b")


def load(inp, cap: dict) -> None:
    inp.extra[cap["name"]] = {"peer_check": load_markdown_table(inp, *PEER_CHECK)}


def build(ctx, ch: dict) -> None:
    table = ctx.inp.extra[ch["name"]]["peer_check"]
    known = ctx.req_ids | ctx.asm_ids | ctx.hazard_ids
    rows = []
    for r in table:
        ids = sorted(set(ID_TOKEN.findall(" ".join(r.values()))))
        unknown = [i for i in ids if i not in known]
        if unknown:
            ctx.problem(f"peer cross-check (spec/{PEER_CHECK[0]} §7) names unknown identifier(s) "
                        f"{', '.join(unknown)}")
        rows.append({"cells": list(r.values()), "ids": ids})
    ch["peer_header"] = list(table[0].keys()) if table else []
    ch["peer_rows"] = rows
