"""Generate the C++ constants header and the Promela #define header from spec/parameters.

The parameters are validated first (every value within the type and range of its unit,
spec/schemas/parameters.schema.json); nothing is written unless every file passes, and the
headers of all areas are written as one set (files.write_all)."""
from __future__ import annotations

import math
import re
from pathlib import Path

from . import SPEC_DIR, add_command
from . import spec as spec_mod
from .files import write_all

_IDENT = re.compile(r"^[a-z][a-z0-9_]*$")


def _literal(file, pid, v, bits):
    """The C++ (bits 64) or Promela (bits 32) literal of a value validate has passed; the
    writer's own last guard: a value its target cannot hold is refused, never written."""
    if isinstance(v, int) and not isinstance(v, bool) and -(1 << bits - 1) <= v < 1 << bits - 1:
        return f"std::int64_t{{{v}}}" if bits == 64 else str(v)
    if bits == 64 and isinstance(v, float) and math.isfinite(v):
        return repr(v)
    raise spec_mod.SpecError(file, pid, f"value {v!r} is not a finite number or an integer of "
                                        f"{bits} bits")


def generate(spec_dir: Path, out_dir: Path):
    from .validate import validate_spec; validate_spec(spec_dir)  # noqa: E702
    areas = spec_mod.load_parameters(spec_dir)
    outputs = {}
    for area, data in sorted(areas.items()):
        name = area.lower()
        if Path(data["file"]).stem != name:  # the build declares <file stem>_params.* as outputs
            raise spec_mod.SpecError(data["file"], "area",
                                     f"area {area} generates {name}_params.*: the file must be "
                                     f"named {name}.yaml")
        lines = [
            "// Generated from spec/parameters by railproof_testgen gen-params. Do not edit.",
            "#pragma once",
            "#include <cstdint>",
            f"namespace railproof::params::{name} {{",
        ]
        pml = [f"/* Generated from {Path(data['file']).name} by railproof_testgen. Do not edit. */"]
        for section, ns in (("parameters", None), ("model_bounds", "model")):
            entries = data[section]
            if ns:
                lines.append(f"namespace {ns} {{")
            for pid, e in entries.items():
                if not _IDENT.match(pid):
                    raise spec_mod.SpecError(data["file"], pid, "id must match [a-z][a-z0-9_]*")
                lines.append(f"inline constexpr auto {pid} = "
                             f"{_literal(data['file'], pid, e['value'], 64)};")
                if section == "model_bounds" and isinstance(e["value"], int):
                    pml.append(f"#define {pid.upper()} {_literal(data['file'], pid, e['value'], 32)}")
            if ns:
                lines.append(f"}}  // namespace {ns}")
        lines.append(f"}}  // namespace railproof::params::{name}")
        outputs[Path(out_dir) / "include/railproof/generated" / f"{name}_params.hpp"] = \
            "\n".join(lines) + "\n"
        outputs[Path(out_dir) / "models" / f"{name}_params.pml"] = "\n".join(pml) + "\n"
    write_all(outputs)


def register(sub):
    add_command(sub, "gen-params", lambda a: generate(Path(a.spec), Path(a.out)),
                "validate spec/ and generate parameter headers",
                spec=SPEC_DIR, out="output directory (build/gen)")
