"""The configuration a package was rendered from (OUT/inputs/configuration.json, shown on the
tool-versions page and hashed in the manifest like every other input):

- source: the commit and tree of the repository (git), the commit's date, and whether the
  working tree differed from the commit when the package was rendered (the changed paths);
- sources: the SHA-256 of every source file (git's tracked files as they are in the working
  tree; without git, every file under the project's source folders) and one digest over the
  sorted list, so that a package names the exact sources even where no commit does;
- build: the build type, compiler, the project's options (RAILPROOF_*) and the compiler flags
  of the runtime and of the rest of the code, from the build directory's CMakeCache.txt and
  compile_commands.json, with the source and build directories written as <src> and <build>
  so that two clones of one commit give the same record.

Everything is read at render time; a missing git or build file gives null and a reason,
never a guess.
"""
from __future__ import annotations

import hashlib
import json
import re
import shlex
import subprocess
from pathlib import Path

from .text import sha256_file

SCHEMA = "railproof/configuration/1"
# the project's sources when there is no git: its top-level source folders and files
SOURCE_FOLDERS = ("spec", "models", "proofs", "testgen", "cpp", "cmake", "evidence", ".ci")
SOURCE_FILES = ("CMakeLists.txt", "CMakePresets.json", "railproof", "README.md")
CACHE_KEYS = ("CMAKE_BUILD_TYPE", "CMAKE_CXX_COMPILER", "CMAKE_CXX_FLAGS")
MAX_CHANGED = 50


def _git(repo: Path, *args: str) -> str | None:
    try:
        r = subprocess.run(["git", "-C", str(repo), *args], capture_output=True, text=True, check=False)
    except FileNotFoundError:
        return None
    return r.stdout if r.returncode == 0 else None


def source_identity(repo: Path) -> dict:
    head = _git(repo, "rev-parse", "HEAD")
    if head is None:
        return {"method": "files", "commit": None, "tree": None, "commit_date": None, "dirty": None,
                "changed": [], "reason": "not a git checkout (or git not installed): the sources are "
                                        "identified by their hashes only"}
    status = _git(repo, "status", "--porcelain", "--untracked-files=no") or ""
    changed = sorted(line[3:] for line in status.splitlines() if line.strip())
    return {"method": "git", "commit": head.strip(), "tree": (_git(repo, "rev-parse", "HEAD^{tree}") or "").strip(),
            "commit_date": (_git(repo, "show", "-s", "--format=%cI", "HEAD") or "").strip(),
            "dirty": bool(changed), "changed": changed[:MAX_CHANGED], "changed_count": len(changed)}


def source_files(repo: Path, method: str) -> list:
    if method == "git":
        listed = (_git(repo, "ls-files", "-z") or "").split("\0")
        paths = sorted(p for p in listed if p and (repo / p).is_file())
    else:
        paths = sorted({p.relative_to(repo).as_posix() for d in SOURCE_FOLDERS if (repo / d).is_dir()
                        for p in (repo / d).rglob("*") if p.is_file() and "__pycache__" not in p.parts}
                       | {f for f in SOURCE_FILES if (repo / f).is_file()})
    return [{"path": p, "sha256": sha256_file(repo / p)} for p in paths]


def _cache(build: Path) -> dict:
    f = build / "CMakeCache.txt"
    if not f.is_file():
        return {}
    out = {}
    for line in f.read_text(encoding="utf-8", errors="replace").splitlines():
        m = re.match(r"^([A-Za-z_][A-Za-z0-9_]*):[A-Z]+=(.*)$", line)
        if m and (m.group(1) in CACHE_KEYS or m.group(1).startswith("CMAKE_CXX_FLAGS_")
                  or m.group(1).startswith("RAILPROOF_")):
            out[m.group(1)] = m.group(2)
    return out


def _flags(command: str, repo: Path, build: Path) -> str:
    """The compile command's flags, without the compiler, its input, output, dependency files
    and include directories (which name the module, not how it is compiled); a path left is
    written with the source and build directories as <src> and <build>."""
    args = shlex.split(command)[1:]
    keep, skip = [], False
    for a in args:
        if skip:
            skip = False
            continue
        if a in ("-o", "-c", "-MF", "-MT", "-MQ", "-I", "-isystem"):
            skip = True
            continue
        if a in ("-MD", "-MMD") or a.startswith(("-I", "-isystem")):
            continue
        keep.append(a.replace(str(build), "<build>").replace(str(repo), "<src>"))
    return " ".join(keep)


def _kind(f: Path, flags: str, repo: Path) -> str:
    if f.is_relative_to(repo / "cpp" / "runtime") and "src" in f.parts:
        if "-DRAILPROOF_SEEDED_FAULTS" in flags:
            return "runtime, seeded-fault variants (tests only)"
        return "runtime, fuzzing builds (tests only)" if "-fsanitize=fuzzer" in flags else "runtime"
    return "other (tests, offline tools, benchmarks)"


def build_identity(repo: Path, build: Path) -> dict:
    cache = _cache(build)
    if not cache:
        return {"build_dir_found": False, "reason": f"no CMakeCache.txt in the build directory ({build.name})"}
    flags: dict = {}
    cc = build / "compile_commands.json"
    if cc.is_file():
        for e in json.loads(cc.read_text(encoding="utf-8")):
            f = _flags(e.get("command") or shlex.join(e.get("arguments", [])), repo, build)
            flags.setdefault(_kind(Path(e["file"]), f, repo), set()).add(f)
    build_type = cache.get("CMAKE_BUILD_TYPE", "")
    return {"build_dir_found": True, "build_type": build_type, "compiler": cache.get("CMAKE_CXX_COMPILER"),
            "config_flags": cache.get(f"CMAKE_CXX_FLAGS_{build_type.upper()}", ""),
            "options": {k: v for k, v in sorted(cache.items()) if k.startswith("RAILPROOF_")
                        and not v.startswith("/")},
            # the runtime's own flags first
            "compile_flags": {k: sorted(flags[k])
                              for k in sorted(flags, key=lambda k: (not k.startswith("runtime"), k))},
            "compile_commands": cc.is_file()}


def collect(repo: Path, build: Path) -> dict:
    repo, build = Path(repo).resolve(), Path(build).resolve()
    src = source_identity(repo)
    files = source_files(repo, src["method"])
    digest = hashlib.sha256("".join(f"{f['sha256']}  {f['path']}\n" for f in files).encode()).hexdigest()
    return {"schema": SCHEMA, "source": src,
            "sources": {"count": len(files), "sha256": digest, "files": files},
            "build": build_identity(repo, build)}
