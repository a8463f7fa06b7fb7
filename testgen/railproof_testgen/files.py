"""Writing result files: completely or not at all (every command's outputs go through here)."""
from __future__ import annotations

import json
from pathlib import Path


def write_atomic(path: Path, text: str, if_changed: bool = True):
    """Write text to path (and its directory), completely or not at all: a temporary file
    renamed over it, removed if that fails, so a reader never sees a half-written file. With
    if_changed a file that already holds the text is left alone (its time stamp too)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if if_changed and path.exists() and path.read_text(encoding="utf-8") == text:
        return
    tmp = path.with_name(path.name + ".tmp")
    try:
        tmp.write_text(text, encoding="utf-8")
        tmp.replace(path)
    finally:
        tmp.unlink(missing_ok=True)


def write_json(path: Path, obj, if_changed: bool = True):
    """obj as JSON (indent 2, keys sorted, final newline), atomically (write_atomic)."""
    write_atomic(path, json.dumps(obj, indent=2, sort_keys=True) + "\n", if_changed=if_changed)
