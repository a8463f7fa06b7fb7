"""Record the versions of every tool that produced evidence (results/tool-versions.json, shown
in the evidence package, which also names the versions of DOC_PACKAGES it was rendered with)."""
from __future__ import annotations

import platform
import re
import subprocess
from importlib import metadata
from pathlib import Path

from . import add_command
from .files import write_json

DEBIAN_PACKAGES = ["spin", "cmake", "ninja-build", "g++", "clang", "libgtest-dev", "libbenchmark-dev",
                   "libsodium-dev", "coinor-libipopt-dev", "libompl-dev", "libbox2d-dev", "nlohmann-json3-dev",
                   "gcovr"]
# the documentation tool chain that renders the evidence package
DOC_PACKAGES = ["Sphinx", "sphinx-needs", "sphinx-test-reports", "docutils", "Jinja2", "PyYAML"]
# and the Python tools whose results it shows (schemas, tests, the two SMT solvers)
PYTHON_PACKAGES = DOC_PACKAGES + ["jsonschema", "pytest", "z3-solver", "cvc5"]


def package_versions(names) -> dict:
    """{distribution: installed version or "not installed"} of the current Python."""
    out = {}
    for name in names:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out


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
    out = {"debian_packages": deb, "python": platform.python_version(),
           "python_packages": package_versions(PYTHON_PACKAGES),
           "spin": _cmd(["spin", "-V"])}
    if compiler:
        out["compiler"] = _cmd([compiler, "--version"])
    os_release = Path("/etc/os-release")
    if os_release.exists():
        m = re.search(r'^PRETTY_NAME="?(.*?)"?$', os_release.read_text(), re.M)
        out["os"] = m.group(1) if m else None
    return out


def register(sub):
    def run(a):
        write_json(Path(a.out), collect(a.compiler), if_changed=False)

    add_command(sub, "toolversions", run, "write the versions of the tool chain as JSON",
                out={"required": True}, compiler={"default": None})
