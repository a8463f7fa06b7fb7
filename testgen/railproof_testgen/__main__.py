"""Command line: python -m railproof_testgen <command> ... (see --help).

Each command lives in the module of its name (``registry``, ``vectors``, ``evidence`` ...),
which exposes ``register(subparsers)``: the module adds its sub-parser and sets ``func`` to a
callable taking the parsed args. Only the module of the command being run is imported (so a
build step depends on the modules it runs, not on every command), and adding a command
needs no edit here: a module of the package with ``register`` is a command. Two commands
carry names other than their module's (ALIASES).
"""
from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
from pathlib import Path

from .errors import PipelineError, SpecError

# command -> module, where they differ
ALIASES = {"gen-params": "params", "verify": "spin"}


def _module_names() -> list:
    return sorted(m.name for m in pkgutil.iter_modules([str(Path(__file__).parent)])
                  if not m.name.startswith("_"))


def build_parser(command: str | None = None):
    ap = argparse.ArgumentParser(
        prog="railproof_testgen",
        description="railproof specification, model-checking, vector and evidence tooling")
    sub = ap.add_subparsers(dest="cmd", required=True)
    module = ALIASES.get(command, command) if command else None
    names = [module] if module in _module_names() else _module_names()
    for name in names:
        mod = importlib.import_module(f".{name}", __package__)
        if hasattr(mod, "register"):
            mod.register(sub)
    return ap


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    command = next((a for a in argv if not a.startswith("-")), None)
    a = build_parser(command).parse_args(argv)
    try:
        rc = a.func(a)
    except (SpecError, PipelineError) as exc:
        print(f"railproof_testgen: error: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:  # a file no loader or writer of the package reported itself
        print(f"railproof_testgen: error: {exc.filename or '-'}: -: {exc.strerror or exc}",
              file=sys.stderr)
        return 1
    return int(rc or 0)


if __name__ == "__main__":
    sys.exit(main())
