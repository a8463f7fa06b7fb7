"""Writing result files: completely or not at all (every command's outputs go through here).

A command that writes several files writes them as one set (write_all): each is first
written in full to a temporary file beside it, and only when every one of them is written
are they renamed over their targets. A failure on the way (an output path that is a
directory, a directory that cannot be written, a full disk) removes every temporary file
and every directory made for the set, and is reported as ``file: -: reason`` (OutputError),
with no target touched; the renames that follow cannot fail on the file system's content
alone, and a failure among them still leaves each target either old or new, never partial.
"""
from __future__ import annotations

import json
import os
import secrets
from pathlib import Path

from .errors import OutputError


def write_all(files, if_changed: bool = True):
    """Write every (path, text) of `files` (a mapping or pairs) as one set, as above. With
    if_changed a file that already holds its text is left alone (its time stamp too)."""
    staged, made = [], []
    path = None
    try:
        for path, text in (files.items() if isinstance(files, dict) else files):
            path = Path(path)
            if path.is_dir():
                raise IsADirectoryError(21, "is a directory, not a file")
            _make_dirs(path.parent, made)
            data = text.encode("utf-8")
            if if_changed and _holds(path, data):
                continue
            tmp = path.with_name(f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp")
            with tmp.open("xb") as fh:
                staged.append((tmp, path))
                fh.write(data)
        for tmp, path in staged:
            tmp.replace(path)
    except OSError as exc:
        for tmp, _ in staged:
            tmp.unlink(missing_ok=True)
        for d in reversed(made):
            try:
                d.rmdir()
            except OSError:
                pass
        raise OutputError(path, "-", f"cannot write: {exc.strerror or exc}") from None


def _make_dirs(d: Path, made: list):
    """Make directory d and its missing parents, recording each one made (for the removal on
    failure)."""
    missing = []
    while not d.is_dir():
        if d.exists() or d.is_symlink():
            raise NotADirectoryError(20, f"{d} is not a directory")
        missing.append(d)
        d = d.parent
    for m in reversed(missing):
        m.mkdir()
        made.append(m)


def _holds(path: Path, data: bytes) -> bool:
    try:
        return path.is_file() and path.read_bytes() == data
    except OSError:
        return False


def write_atomic(path: Path, text: str, if_changed: bool = True):
    """Write text to path (and its directory), completely or not at all (write_all of one
    file), so a reader never sees a half-written file."""
    write_all({Path(path): text}, if_changed=if_changed)


def write_json(path: Path, obj, if_changed: bool = True):
    """obj as JSON (indent 2, keys sorted, final newline), atomically (write_atomic)."""
    write_atomic(path, json.dumps(obj, indent=2, sort_keys=True) + "\n", if_changed=if_changed)
