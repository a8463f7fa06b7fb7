"""Command line: python -m railproof_testgen <command> ... (see --help).

Each command lives in its own module, which exposes ``register(subparsers)``; the
module adds its sub-parser and sets ``func`` to a callable taking the parsed args.
"""
from __future__ import annotations

import argparse
import importlib
import sys

from .errors import PipelineError, SpecError

COMMAND_MODULES = ["registry", "layout", "params", "validate", "lines", "trace", "spin", "vectors", "evidence",
                   "toolversions", "trains", "timetables", "proofs"]


def build_parser():
    ap = argparse.ArgumentParser(
        prog="railproof_testgen",
        description="railproof specification, model-checking, vector and evidence tooling")
    sub = ap.add_subparsers(dest="cmd", required=True)
    for name in COMMAND_MODULES:
        try:
            mod = importlib.import_module(f".{name}", __package__)
        except ModuleNotFoundError as exc:
            if exc.name and exc.name.endswith(f"railproof_testgen.{name}"):
                continue  # command not present in this tree
            raise
        if hasattr(mod, "register"):
            mod.register(sub)
    return ap


def main(argv=None):
    a = build_parser().parse_args(argv)
    try:
        rc = a.func(a)
    except (SpecError, PipelineError) as exc:
        print(f"railproof_testgen: error: {exc}", file=sys.stderr)
        return 1
    return int(rc or 0)


if __name__ == "__main__":
    sys.exit(main())
