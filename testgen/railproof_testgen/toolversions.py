"""Record the versions of every tool that produced evidence (for the evidence package)."""
from __future__ import annotations

import json
import platform
import re
import subprocess
from importlib import metadata
from pathlib import Path

DEBIAN_PACKAGES = ["spin", "cmake", "ninja-build", "g++", "clang", "libgtest-dev", "libbenchmark-dev",
                   "libsodium-dev", "coinor-libipopt-dev", "libompl-dev", "libbox2d-dev", "nlohmann-json3-dev",
                   "gcovr"]
PYTHON_PACKAGES = ["Sphinx", "sphinx-needs", "sphinx-test-reports", "PyYAML", "jsonschema", "pytest"]


def _cmd(args):
    try:
        r = subprocess.run(args, capture_output=True, text=True, check=False)
    except FileNotFoundError:
        return None
    return (r.stdout or r.stderr).strip().splitlines()[0] if (r.stdout or r.stderr) else None


def collect(compiler: str | None = None) -> dict:
    deb = {}
    for pkg in DEBIAN_PACKAGES:
        v = _cmd(["dpkg-query", "-W", "-f=${Version}", pkg])
        deb[pkg] = v if v and not v.startswith("dpkg-query") else "not installed"
    py = {}
    for pkg in PYTHON_PACKAGES:
        try:
            py[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            py[pkg] = "not installed"
    out = {"debian_packages": deb, "python": platform.python_version(), "python_packages": py,
           "spin": _cmd(["spin", "-V"])}
    if compiler:
        out["compiler"] = _cmd([compiler, "--version"])
    os_release = Path("/etc/os-release")
    if os_release.exists():
        m = re.search(r'^PRETTY_NAME="?(.*?)"?$', os_release.read_text(), re.M)
        out["os"] = m.group(1) if m else None
    return out


def register(sub):
    p = sub.add_parser("toolversions", help="write the versions of the tool chain as JSON")
    p.add_argument("--out", required=True)
    p.add_argument("--compiler", default=None)

    def run(a):
        path = Path(a.out)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(".tmp")
        tmp.write_text(json.dumps(collect(a.compiler), indent=2, sort_keys=True) + "\n", encoding="utf-8")
        tmp.replace(path)
    p.set_defaults(func=run)
