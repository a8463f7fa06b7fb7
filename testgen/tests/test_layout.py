"""The module-boundary check (railproof_testgen layout): a tiny target graph and source tree
per case; every rule must be able to fail."""
from __future__ import annotations

import json

import pytest

GOOD = {
    "railproof_core": {"kind": "runtime:common:", "links": []},
    "railproof_messages": {"kind": "runtime:common:", "links": ["railproof_core"]},
    "railproof_xx_common": {"kind": "runtime:common:xx", "links": ["railproof_core", "PkgConfig::SODIUM"]},
    "railproof_xx_onboard": {"kind": "runtime:onboard:xx", "links": ["railproof_xx_common", "railproof_messages"]},
    "railproof_xx_wayside": {"kind": "runtime:wayside:xx", "links": ["railproof_xx_common", "railproof_messages"]},
    "railproof_offline": {"kind": "offline", "links": ["railproof_xx_onboard", "nlohmann_json::nlohmann_json"]},
    "railproof_xx_tests": {"kind": "test:runtime:xx", "links": ["railproof_xx_onboard", "railproof_xx_wayside"]},
    "railproof_offline_tests": {"kind": "test:offline:", "links": ["railproof_offline"]},
}


def _repo(tmp_path, targets, files=None):
    (tmp_path / "targets.json").write_text(json.dumps({"schema": "railproof/targets/1", "targets": targets}),
                                           encoding="utf-8")
    base = {
        "cpp/runtime/xx/src/onboard/a.cpp": '#include "railproof/xx/onboard/a.hpp"\n#include "railproof/messages/m.hpp"\n',
        "cpp/runtime/xx/src/wayside/b.cpp": '#include "railproof/xx/b.hpp"\n',
        "cpp/runtime/xx/tests/test_a.cpp": '#include "railproof/testing/alloc_counter.hpp"\n'
                                           '#include "railproof/xx/wayside/b.hpp"\n',
    }
    base.update(files or {})
    for rel, text in base.items():
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text, encoding="utf-8")
    return tmp_path


def _run(cli, root):
    return cli("layout", "--repo", root, "--targets", root / "targets.json", "--out", root / "layout.json")


def test_a_clean_graph_passes_and_records_the_closures(cli, tmp_path):
    root = _repo(tmp_path, GOOD)
    r = _run(cli, root)
    assert r.rc == 0, r.err
    data = json.loads((root / "layout.json").read_text(encoding="utf-8"))
    assert data["violations"] == []
    assert data["targets"]["railproof_xx_onboard"]["closure"] == sorted(
        ["railproof_xx_common", "railproof_messages", "railproof_core", "PkgConfig::SODIUM"])


@pytest.mark.parametrize("target, links, fragment", [
    ("railproof_xx_onboard", ["railproof_xx_common", "railproof_offline"], "a runtime module links offline code"),
    ("railproof_xx_onboard", ["railproof_xx_wayside"], "onboard code links wayside code"),
    ("railproof_xx_wayside", ["railproof_messages", "railproof_xx_onboard"], "wayside code links onboard code"),
    ("railproof_xx_common", ["railproof_xx_onboard"], "a common part links onboard code"),
    ("railproof_xx_common", ["box2d::box2d"], "a runtime module links an external library"),
    ("railproof_xx_tests", ["railproof_xx_onboard", "railproof_offline"], "a runtime test links offline code"),
])
def test_every_link_rule_can_fail(cli, tmp_path, target, links, fragment):
    targets = json.loads(json.dumps(GOOD))
    targets[target]["links"] = links
    r = _run(cli, _repo(tmp_path, targets))
    assert r.rc == 1
    assert any(ln.startswith(f"{target}: ") and fragment in ln for ln in r.lines), r.err


def test_a_transitive_link_is_found(cli, tmp_path):
    """The closure, not the direct links: onboard -> common -> (wrongly) offline."""
    targets = json.loads(json.dumps(GOOD))
    targets["railproof_xx_common"]["links"] = ["railproof_core", "railproof_offline_tests"]
    r = _run(cli, _repo(tmp_path, targets))
    assert r.rc == 1
    assert any(ln.startswith("railproof_xx_onboard: railproof_offline_tests: a runtime module links test code")
               for ln in r.lines), r.err


@pytest.mark.parametrize("rel, text, fragment", [
    ("cpp/runtime/xx/src/onboard/c.cpp", '#include "railproof/offline/line.hpp"\n',
     "line 1: runtime code includes railproof/offline/line.hpp"),
    ("cpp/runtime/xx/src/onboard/c.cpp", '\n#include "railproof/xx/analysis/study.hpp"\n',
     "line 2: runtime code includes railproof/xx/analysis/study.hpp"),
    ("cpp/runtime/xx/include/railproof/xx/onboard/c.hpp", '#include "railproof/yy/wayside/g.hpp"\n',
     "line 1: onboard code includes railproof/yy/wayside/g.hpp"),
    ("cpp/runtime/xx/src/wayside/c.cpp", '#include "railproof/xx/onboard/a.hpp"\n',
     "line 1: wayside code includes railproof/xx/onboard/a.hpp"),
    ("cpp/runtime/xx/src/c.cpp", '#include "railproof/xx/wayside/b.hpp"\n',
     "line 1: common code includes railproof/xx/wayside/b.hpp"),
])
def test_every_include_rule_can_fail(cli, tmp_path, rel, text, fragment):
    r = _run(cli, _repo(tmp_path, GOOD, {rel: text}))
    assert r.rc == 1
    assert any(ln.startswith(rel) and fragment in ln for ln in r.lines), r.err


def test_test_code_may_include_both_sides_and_test_support(cli, tmp_path):
    """tests/, conformance/, bench/ and fuzz/ of a module are test code, not the module."""
    r = _run(cli, _repo(tmp_path, GOOD, {
        "cpp/runtime/xx/conformance/run.cpp": '#include "railproof/xx/onboard/a.hpp"\n#include "railproof/xx/wayside/b.hpp"\n',
        "cpp/runtime/xx/bench/bench.cpp": '#include "railproof/offline/line.hpp"\n'}))
    assert r.rc == 0, r.err


def test_a_missing_or_malformed_target_list_is_a_clear_error(cli, tmp_path):
    r = cli("layout", "--repo", tmp_path, "--targets", tmp_path / "none.json")
    assert r.rc == 1 and "no target list (configure the build first)" in r.err
    (tmp_path / "bad.json").write_text("{", encoding="utf-8")
    r = cli("layout", "--repo", tmp_path, "--targets", tmp_path / "bad.json")
    assert r.rc == 1 and "malformed target list" in r.err
