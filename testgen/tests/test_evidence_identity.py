"""The configuration record of the evidence package (railproof_testgen.evidence.identity):
commit, tree and working-tree state from git, the hashes of the source files, and the build's
type, options and compile flags with the checkout's paths taken out."""
from __future__ import annotations

import hashlib
import json
import shutil
import subprocess
from pathlib import Path

import pytest

from railproof_testgen.evidence import identity

needs_git = pytest.mark.skipif(shutil.which("git") is None, reason="git not installed")


def _git(repo: Path, *args: str) -> str:
    return subprocess.run(["git", "-C", str(repo), *args], check=True, capture_output=True, text=True).stdout.strip()


def _checkout(tmp_path: Path) -> Path:
    repo = tmp_path / "repo"
    (repo / "cpp/runtime/ra/src").mkdir(parents=True)
    (repo / "cpp/runtime/ra/tests").mkdir(parents=True)
    (repo / "cpp/runtime/ra/src/a.cpp").write_text("int a() { return 1; }\n")
    (repo / "cpp/runtime/ra/tests/t.cpp").write_text("int t() { return 2; }\n")
    (repo / "README.md").write_text("readme\n")
    build = repo / "build"
    build.mkdir()
    (build / "CMakeCache.txt").write_text(
        "CMAKE_BUILD_TYPE:STRING=RelWithDebInfo\nCMAKE_CXX_COMPILER:UNINITIALIZED=clang++\n"
        "CMAKE_CXX_FLAGS_RELWITHDEBINFO:STRING=-O2 -DNDEBUG\nRAILPROOF_WERROR:BOOL=ON\n"
        f"RAILPROOF_CONFORMANCE_VECTORS:PATH={build}/results/vectors\nOTHER:STRING=x\n")
    cmds = [{"directory": str(build), "file": str(repo / "cpp/runtime/ra/src/a.cpp"),
             "command": f"/usr/bin/clang++ -I{repo}/cpp/runtime/ra/include -I {build}/gen/include -O2 "
                        f"-DNDEBUG -std=c++20 -MD -MF x.d -o a.o -c {repo}/cpp/runtime/ra/src/a.cpp"},
            {"directory": str(build), "file": str(repo / "cpp/runtime/ra/src/a.cpp"),
             "command": f"/usr/bin/clang++ -DRAILPROOF_SEEDED_FAULTS -O2 -std=c++20 -o f.o "
                        f"-c {repo}/cpp/runtime/ra/src/a.cpp"},
            {"directory": str(build), "file": str(repo / "cpp/runtime/ra/tests/t.cpp"),
             "command": f"/usr/bin/clang++ -DDATA=\"{build}/gen\" -O0 -std=c++20 -o t.o "
                        f"-c {repo}/cpp/runtime/ra/tests/t.cpp"}]
    (build / "compile_commands.json").write_text(json.dumps(cmds))
    return repo


@needs_git
def test_commit_tree_sources_and_build_of_a_checkout(tmp_path):
    repo = _checkout(tmp_path)
    (repo / ".gitignore").write_text("build/\n")
    _git(repo, "init", "-q")
    _git(repo, "add", ".")
    _git(repo, "-c", "user.name=x", "-c", "user.email=x@x", "commit", "-q", "-m", "one")
    rec = identity.collect(repo, repo / "build")
    assert rec["schema"] == identity.SCHEMA
    src = rec["source"]
    assert (src["method"], src["commit"], src["tree"]) == ("git", _git(repo, "rev-parse", "HEAD"),
                                                           _git(repo, "rev-parse", "HEAD^{tree}"))
    assert src["dirty"] is False and src["changed"] == []
    files = rec["sources"]["files"]
    assert [f["path"] for f in files] == [".gitignore", "README.md", "cpp/runtime/ra/src/a.cpp",
                                          "cpp/runtime/ra/tests/t.cpp"]
    assert files[1]["sha256"] == hashlib.sha256(b"readme\n").hexdigest()
    assert rec["sources"]["count"] == 4
    b = rec["build"]
    assert (b["build_type"], b["compiler"], b["config_flags"]) == ("RelWithDebInfo", "clang++", "-O2 -DNDEBUG")
    assert b["options"] == {"RAILPROOF_WERROR": "ON"}  # an option naming a path of the checkout is left out
    assert b["compile_flags"] == {
        "other (tests, offline tools, benchmarks)": ['-DDATA=<build>/gen -O0 -std=c++20'],
        "runtime": ["-O2 -DNDEBUG -std=c++20"],
        "runtime, seeded-fault variants (tests only)": ["-DRAILPROOF_SEEDED_FAULTS -O2 -std=c++20"]}
    # an edit after the commit: the working tree differs, the file's hash is the edited one
    (repo / "README.md").write_text("edited\n")
    rec2 = identity.collect(repo, repo / "build")
    assert rec2["source"]["dirty"] is True and rec2["source"]["changed"] == ["README.md"]
    assert rec2["sources"]["sha256"] != rec["sources"]["sha256"]
    # a second clone of the same commit gives the same record
    clone = tmp_path / "clone"
    subprocess.run(["git", "clone", "-q", str(repo), str(clone)], check=True)
    shutil.copytree(repo / "build", clone / "build")
    for name in ("CMakeCache.txt", "compile_commands.json"):
        f = clone / "build" / name
        f.write_text(f.read_text().replace(str(repo), str(clone)))
    (repo / "README.md").write_text("readme\n")
    assert identity.collect(clone, clone / "build") == identity.collect(repo, repo / "build")


def test_without_git_or_build_the_record_says_so(tmp_path, monkeypatch):
    repo = _checkout(tmp_path)
    monkeypatch.setattr(identity, "_git", lambda *a: None)  # no git checkout
    rec = identity.collect(repo, tmp_path / "no-build")
    assert rec["source"]["commit"] is None and "not a git checkout" in rec["source"]["reason"]
    assert [f["path"] for f in rec["sources"]["files"]] == ["README.md", "cpp/runtime/ra/src/a.cpp",
                                                            "cpp/runtime/ra/tests/t.cpp"]
    assert rec["build"] == {"build_dir_found": False, "reason": "no CMakeCache.txt in the build directory (no-build)"}
