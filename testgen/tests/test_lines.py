"""Line data (spec/lines, REQ-MB-020): the provided lines validate and convert to the line
JSON contract; every topology rule rejects a broken entry with 'file: entry: reason'
naming the entry; nothing is written on error; the output is deterministic."""
from __future__ import annotations

import json
import shutil

import pytest

from conftest import FIXTURES, REPO, fails_with
from railproof_testgen import lines
from railproof_testgen.errors import SpecError

LINE_FIXTURES = FIXTURES / "lines"
MINI = "lines/mini_line.yaml"
PROVIDED = ["d1_test_line", "d2_urban_line", "d4_local_line"]


@pytest.fixture
def line_spec(tmp_path):
    """line_spec(*edits, extra=None) -> spec dir holding the miniature line with the text
    edits (old, new) applied, the real line schema and a one-entry assumptions file."""

    def make(*edits, extra=None):
        spec = tmp_path / "spec"
        if spec.exists():
            shutil.rmtree(spec)
        (spec / "lines").mkdir(parents=True)
        (spec / "schemas").mkdir()
        (spec / "assumptions").mkdir()
        shutil.copy(REPO / "spec/schemas/line.schema.json", spec / "schemas")
        shutil.copy(LINE_FIXTURES / "assumptions.yaml", spec / "assumptions")
        text = (LINE_FIXTURES / "mini_line.yaml").read_text(encoding="utf-8")
        for old, new in edits:
            assert text.count(old) == 1, f"{old!r} must occur exactly once in mini_line.yaml"
            text = text.replace(old, new)
        (spec / "lines" / "mini_line.yaml").write_text(text, encoding="utf-8")
        for name, content in (extra or {}).items():
            (spec / name).parent.mkdir(parents=True, exist_ok=True)
            (spec / name).write_text(content, encoding="utf-8")
        return spec

    return make


def contract_problems(obj):
    """The rules the C++ loader (cpp/offline/common/src/line.cpp) applies to the line JSON."""
    bad = []
    assert obj["schema"] == "railproof/line-json/1"
    for key in ("name", "title", "assumption"):
        assert isinstance(obj[key], str) and obj[key]
    assert obj["source"] and obj["running_lines"]
    for rl in obj["running_lines"]:
        L = rl["length_mm"]
        b = rl["blocks_mm"]
        if b[0] != 0 or b[-1] != L or any(x >= y for x, y in zip(b, b[1:])):
            bad.append(f"{rl['id']}: blocks")
        for key in ("gradients", "speed_limits", "radio_cells"):
            secs = [(s["begin_mm"], s["end_mm"]) for s in rl[key]]
            if secs[0][0] != 0 or secs[-1][1] != L or any(
                    a[1] != c[0] for a, c in zip(secs, secs[1:])) or any(a >= e for a, e in secs):
                bad.append(f"{rl['id']}: {key} do not cover the line")
        for key in ("curves", "no_stop_sections"):
            secs = [(s["begin_mm"], s["end_mm"]) for s in rl[key]]
            if any(c[0] < a[1] for a, c in zip(secs, secs[1:])):
                bad.append(f"{rl['id']}: {key} overlap")
        pos = [x["position_mm"] for x in rl["balises"]]
        if pos != sorted(pos) or any(not 0 <= p <= L for p in pos):
            bad.append(f"{rl['id']}: balises")
        stops = [s["stop_mm"] for s in rl["stations"]]
        if any(x >= y for x, y in zip(stops, stops[1:])):
            bad.append(f"{rl['id']}: stations not sorted by stop")
        for s in rl["stations"]:
            if not s["platform_begin_mm"] < s["stop_mm"] <= s["platform_end_mm"]:
                bad.append(f"{rl['id']}: {s['name']} stop outside its platform")
        pts = {p["id"]: (p["begin_mm"], p["end_mm"]) for p in rl["points"]}
        for pid, (a, e) in pts.items():
            if a not in b or b[b.index(a) + 1] != e:
                bad.append(f"{rl['id']}: points {pid} not exactly one block")
        for r in rl["routes"]:
            a, e = pts[r["points"]]
            if not (r["begin_mm"] < r["end_mm"] and r["begin_mm"] <= a and e <= r["end_mm"]):
                bad.append(f"{rl['id']}: route {r['id']} does not contain its points")
        cell_begins = {c["begin_mm"] for c in rl["radio_cells"] if c["begin_mm"] > 0}
        if {h["position_mm"] for h in rl["handovers"]} != cell_begins:
            bad.append(f"{rl['id']}: handovers not at the cell boundaries")
        sb = rl["system_boundary_mm"]
        if sb is not None and not 0 < sb <= L:
            bad.append(f"{rl['id']}: system boundary")
        prev_far = None
        for lc in rl["level_crossings"]:
            near, far = lines.crossing_extent(lc["position_mm"], lc["width_mm"])
            if not (lc["width_mm"] > 0 and lc["warning_time_ms"] > 0 and 0 < near and far < L):
                bad.append(f"{rl['id']}: level crossing {lc['id']}")
            if prev_far is not None and near < prev_far:
                bad.append(f"{rl['id']}: level crossing {lc['id']} overlaps or is out of order")
            prev_far = far
    return bad


# --------------------------------------------------------------------------- provided lines

def test_provided_lines_validate_and_convert(cli, tmp_path):
    out = tmp_path / "gen"
    r = cli("lines", "--spec", REPO / "spec", "--out", out)
    assert r.rc == 0, r.err
    assert r.lines == []
    assert sorted(p.stem for p in out.glob("*.json")) == PROVIDED
    for name in PROVIDED:
        obj = json.loads((out / f"{name}.json").read_text(encoding="utf-8"))
        assert obj["name"] == name
        assert obj["assumption"] in {"ASM-019", "ASM-020", "ASM-021"}
        assert [rl["id"] for rl in obj["running_lines"]] == ["up", "down"]
        assert contract_problems(obj) == []


def test_provided_lines_match_their_sources(tmp_path):
    lines.generate(REPO / "spec", tmp_path)
    d1 = json.loads((tmp_path / "d1_test_line.json").read_text())
    up = d1["running_lines"][0]
    assert up["length_mm"] == 14_500_000
    assert len(up["blocks_mm"]) - 1 == 290  # 50 m virtual blocks
    assert max(abs(g["permille_x10"]) for g in up["gradients"]) == 159  # +/-15.9 permille
    assert max(s["kmh"] for s in up["speed_limits"]) == 100
    assert up["handovers"] and up["balises"] and up["stations"]
    d4 = json.loads((tmp_path / "d4_local_line.json").read_text())
    assert d4["running_lines"][0]["length_mm"] == 30_500_000
    assert len(d4["running_lines"][0]["stations"]) == 5
    assert len(d4["running_lines"][0]["points"]) == 10  # two per passing loop
    assert d4["running_lines"][0]["level_crossings"]
    d2 = json.loads((tmp_path / "d2_urban_line.json").read_text())
    assert d2["design_train_length_mm"] == 200_000
    assert all(s["fixed_block"] for rl in d2["running_lines"] for s in rl["stations"])


def test_output_is_deterministic(cli, tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    assert cli("lines", "--spec", REPO / "spec", "--out", a).rc == 0
    assert cli("lines", "--spec", REPO / "spec", "--out", b).rc == 0
    for name in PROVIDED:
        assert (a / f"{name}.json").read_bytes() == (b / f"{name}.json").read_bytes()
    before = {p.name: p.read_bytes() for p in a.iterdir()}
    assert cli("lines", "--spec", REPO / "spec", "--out", a).rc == 0
    assert {p.name: p.read_bytes() for p in a.iterdir()} == before
    assert not list(a.glob("*.tmp"))


def test_validate_includes_the_provided_lines():
    from railproof_testgen import validate
    model, report = validate.check_spec(REPO / "spec")
    assert report.errors == []
    assert sorted(model["lines"]) == PROVIDED


# --------------------------------------------------------------------------- miniature line

def test_mini_line_converts_both_directions(line_spec, tmp_path):
    spec = line_spec()
    lines.generate(spec, tmp_path)
    obj = json.loads((tmp_path / "mini_line.json").read_text())
    assert contract_problems(obj) == []
    up, down = obj["running_lines"]
    assert (up["direction"], down["direction"]) == ("increasing", "decreasing")
    assert up["gradients"] == [{"begin_mm": 0, "end_mm": 1_000_000, "permille_x10": 55},
                               {"begin_mm": 1_000_000, "end_mm": 2_000_000, "permille_x10": -30}]
    # mirrored and sign-changed for the opposite direction
    assert down["gradients"] == [{"begin_mm": 0, "end_mm": 1_000_000, "permille_x10": 30},
                                 {"begin_mm": 1_000_000, "end_mm": 2_000_000, "permille_x10": -55}]
    # points are reported as their virtual block
    assert up["points"] == [{"id": "P1", "begin_mm": 800_000, "end_mm": 900_000},
                            {"id": "P2", "begin_mm": 1_100_000, "end_mm": 1_200_000}]
    assert down["points"] == [{"id": "P2", "begin_mm": 800_000, "end_mm": 900_000},
                              {"id": "P1", "begin_mm": 1_100_000, "end_mm": 1_200_000}]
    assert [(r["id"], r["begin_mm"], r["end_mm"], r["reverse"], r["automatic"])
            for r in down["routes"]] == [(3, 600_000, 1_040_000, True, True),
                                         (4, 600_000, 1_040_000, False, False)]
    # the down stop lies on the loop platform, mapped onto the main track's running line
    assert down["stations"] == [{"name": "ST", "platform": "ST-2", "platform_begin_mm": 960_000,
                                 "platform_end_mm": 1_040_000, "stop_mm": 1_035_000,
                                 "fixed_block": True, "setback": False}]
    assert up["stations"][0]["stop_mm"] == 1_035_000
    assert [b["id"] for b in up["balises"]] == ["B1", "B2"]  # B3 lies on the loop
    assert [b["id"] for b in down["balises"]] == ["B2", "B1"]
    assert up["system_boundary_mm"] == 1_950_000 and down["system_boundary_mm"] is None
    assert down["handovers"] == [{"id": "H1", "position_mm": 1_000_000}]
    assert down["no_stop_sections"] == [{"id": "NS1", "begin_mm": 450_000, "end_mm": 550_000}]
    # crossing: centre mirrored, width and design warning time in mm and ms
    assert down["level_crossings"] == [{"id": "LC1", "position_mm": 500_000, "width_mm": 8_000,
                                        "warning_time_ms": 30_000}]
    assert up["level_crossings"][0]["position_mm"] == 1_500_000
    assert down["kilometre_posts"][0] == {"position_mm": 0, "kilometrage_mm": 12_000_000}
    assert obj["design_train_length_mm"] == 40_000


def test_valid_mini_line_passes(line_spec, cli, tmp_path):
    r = cli("lines", "--spec", line_spec(), "--out", tmp_path / "out")
    assert r.rc == 0, r.err
    assert (tmp_path / "out/mini_line.json").is_file()


BLOCKS = "  - {track: main, from_m: 0, to_m: 2000, length_m: 100}\n"

# (old, new, entry, reason fragment): one broken rule each
CASES = {
    # virtual blocks
    "overlapping_blocks": (
        BLOCKS, "  - {track: main, from_m: 0, to_m: 1000, length_m: 100}\n"
                "  - {track: main, from_m: 900, to_m: 2000, length_m: 100}\n",
        "virtual_blocks[1]", "overlaps virtual_blocks[0]"),
    "gap_between_blocks": (
        BLOCKS, "  - {track: main, from_m: 0, to_m: 1000, length_m: 100}\n"
                "  - {track: main, from_m: 1100, to_m: 2000, length_m: 100}\n",
        "virtual_blocks[1]", "gap [1000, 1100) m after virtual_blocks[0]"),
    "blocks_short_of_the_track_end": (
        "to_m: 2000, length_m: 100}", "to_m: 1900, length_m: 100}",
        "virtual_blocks[0]", "gap [1900, 2000) m not covered"),
    "blocks_not_a_whole_number": (
        "to_m: 2000, length_m: 100}", "to_m: 2000, length_m: 300}",
        "virtual_blocks[0]", "is not a whole number of 300 m blocks"),
    "reversed_block_range": (
        "{track: L1, from_m: 820, to_m: 1180", "{track: L1, from_m: 1180, to_m: 820",
        "virtual_blocks[1]", "empty or reversed range"),
    "track_without_blocks": (
        "  - {track: L1, from_m: 820, to_m: 1180, length_m: 120}\n", "",
        "tracks[L1]", "track has no virtual blocks"),
    "blocks_on_unknown_track": (
        "{track: L1, from_m: 820", "{track: L9, from_m: 820",
        "virtual_blocks[1]", "unknown track 'L9'"),
    # line profile
    "gradients_not_covering_the_line": (
        "{from_m: 1000, to_m: 2000, permille: -3}", "{from_m: 1000, to_m: 1900, permille: -3}",
        "gradients[1]", "gap [1900, 2000) m not covered"),
    "gradients_with_a_gap": (
        "{from_m: 1000, to_m: 2000, permille: -3}", "{from_m: 1100, to_m: 2000, permille: -3}",
        "gradients[1]", "gap [1000, 1100) m after gradients[0] not covered by gradients"),
    "overlapping_gradients": (
        "{from_m: 1000, to_m: 2000, permille: -3}", "{from_m: 900, to_m: 2000, permille: -3}",
        "gradients[1]", "overlaps gradients[0]"),
    "gradient_too_precise": (
        "permille: 5.5}", "permille: 5.55}", "gradients[0]", "not a whole number of 0.1 permille"),
    "speed_limits_with_a_gap": (
        "{from_m: 1000, to_m: 2000, kmh: 60}", "{from_m: 1200, to_m: 2000, kmh: 60}",
        "speed_limits[1]", "gap [1000, 1200) m after speed_limits[0]"),
    "speed_limits_not_from_zero": (
        "{from_m: 0, to_m: 1000, kmh: 80}", "{from_m: 100, to_m: 1000, kmh: 80}",
        "speed_limits[0]", "gap [0, 100) m not covered"),
    "overlapping_curves": (
        "  - {from_m: 300, to_m: 500, radius_m: 600}\n",
        "  - {from_m: 300, to_m: 500, radius_m: 600}\n  - {from_m: 450, to_m: 700, radius_m: 900}\n",
        "curves[1]", "overlaps curves[0]"),
    "curve_off_the_line": (
        "{from_m: 300, to_m: 500, radius_m: 600}", "{from_m: 1900, to_m: 2100, radius_m: 600}",
        "curves[0]", "off the line"),
    # located objects
    "balise_off_the_line": (
        "{id: B2, track: main, at_m: 950}", "{id: B2, track: main, at_m: 2500}",
        "balises[B2]", "balise at 2500 m is off the line"),
    "balise_at_the_line_end": (
        "{id: B2, track: main, at_m: 950}", "{id: B2, track: main, at_m: 2000}",
        "balises[B2]", "off the line"),
    "balise_off_its_loop": (
        "{id: B3, track: L1, at_m: 1000}", "{id: B3, track: L1, at_m: 700}",
        "balises[B3]", "off the line (strictly inside track L1 [820, 1180) m required)"),
    "balise_on_unknown_track": (
        "{id: B3, track: L1,", "{id: B3, track: siding,", "balises[B3]", "unknown track 'siding'"),
    "position_not_whole_mm": (
        "{id: B1, track: main, at_m: 50}", "{id: B1, track: main, at_m: 50.0005}",
        "balises[B1]", "at_m: 50.0005 is not a whole number of millimetres"),
    "level_crossing_off_the_line": (
        "{id: LC1, at_m: 1500,", "{id: LC1, at_m: 2000,", "level_crossings[LC1]", "off the line"),
    "system_boundary_off_the_line": (
        "system_boundary_m: 1950}", "system_boundary_m: 2000}", "running_lines[up]",
        "system boundary at 2000 m is off the line"),
    "no_stop_sections_overlapping": (
        "  - {id: NS1, from_m: 1450, to_m: 1550, reason: level crossing LC1}\n",
        "  - {id: NS1, from_m: 1450, to_m: 1550, reason: level crossing LC1}\n"
        "  - {id: NS2, from_m: 1500, to_m: 1600, reason: feeder section}\n",
        "no_stop_sections[NS2]", "overlaps no_stop_sections[NS1]"),
    # points
    "point_without_a_block": (
        BLOCKS, "  - {track: main, from_m: 0, to_m: 800, length_m: 100}\n"
                "  - {track: main, from_m: 900, to_m: 2000, length_m: 100}\n",
        "points[P1]", "point without a virtual block"),
    "point_spanning_two_blocks": (
        "{id: P1, track: main, from_m: 800, to_m: 820,", "{id: P1, track: main, from_m: 790, to_m: 820,",
        "points[P1]", "span 2 virtual blocks ([700, 800) m, [800, 900) m)"),
    "two_points_in_one_block": (
        "  - {id: P2, track: main,",
        "  - {id: P3, track: main, from_m: 850, to_m: 870, reverse_to: L1}\n  - {id: P2, track: main,",
        "points[P3]", "shares virtual block [800, 900) m with points[P1]"),
    "point_off_the_line": (
        "{id: P2, track: main, from_m: 1180, to_m: 1200,", "{id: P2, track: main, from_m: 1990, to_m: 2010,",
        "points[P2]", "off the line"),
    "point_leading_nowhere": (
        "to_m: 1200, reverse_to: L1}", "to_m: 1200, reverse_to: L7}",
        "points[P2]", "reverse_to: unknown track 'L7'"),
    "loop_not_meeting_its_points": (
        "{id: L1, kind: loop, from_m: 820,", "{id: L1, kind: loop, from_m: 830,",
        "tracks[L1]", "from_m 830 m does not meet points P1 at 820 m"),
    "loop_with_unknown_points": (
        "points: [P1, P2]}", "points: [P1, P9]}", "tracks[L1]", "unknown points 'P9'"),
    "loop_points_leading_elsewhere": (
        "to_m: 820, reverse_to: L1}", "to_m: 820, reverse_to: main}",
        "points[P1]", "reverse_to: leads to its own track 'main'"),
    # routes
    "unknown_points_in_a_route": (
        "{id: 1, running_line: up, entry_m: 600, exit_m: 1040, points: P1,",
        "{id: 1, running_line: up, entry_m: 600, exit_m: 1040, points: P9,",
        "routes[1]", "unknown points 'P9'"),
    "route_on_unknown_running_line": (
        "{id: 2, running_line: up,", "{id: 2, running_line: sideways,",
        "routes[2]", "unknown running line 'sideways'"),
    "route_against_its_direction": (
        "{id: 1, running_line: up, entry_m: 600, exit_m: 1040,",
        "{id: 1, running_line: up, entry_m: 1040, exit_m: 600,",
        "routes[1]", "does not run in the direction of running line up"),
    "route_not_over_its_points": (
        "{id: 1, running_line: up, entry_m: 600,", "{id: 1, running_line: up, entry_m: 850,",
        "routes[1]", "does not contain the virtual block [800, 900) m of its points P1"),
    "duplicate_route_id": (
        "{id: 4, running_line: down,", "{id: 3, running_line: down,",
        "routes[3]", "duplicate id 3 (first used by entry 3 of routes)"),
    # stations and platforms
    "stop_outside_its_platform": (
        "stops: {up: 1035}", "stops: {up: 1045}", "stations[ST].platforms[ST-1]",
        "stops.up: stop point 1045 m is outside the platform [960, 1040) m"),
    "stop_at_the_near_end": (
        "stops: {up: 1035}", "stops: {up: 960}", "stations[ST].platforms[ST-1]",
        "stops.up: stop point 960 m is outside the platform"),
    "down_stop_at_the_far_end_of_the_chainage": (
        "stops: {down: 965}", "stops: {down: 1040}", "stations[ST].platforms[ST-2]",
        "stops.down: stop point 1040 m is outside the platform"),
    "stop_for_unknown_running_line": (
        "stops: {down: 965}", "stops: {sideways: 965}", "stations[ST].platforms[ST-2]",
        "stops.sideways: unknown running line 'sideways'"),
    "two_stops_for_one_running_line": (
        "stops: {down: 965}", "stops: {up: 1035}", "stations[ST].platforms[ST-2]",
        "station ST already has a stop for running line up"),
    "platform_off_its_loop": (
        "{id: ST-2, track: L1, from_m: 960, to_m: 1040, stops: {down: 965}",
        "{id: ST-2, track: L1, from_m: 700, to_m: 780, stops: {down: 705}",
        "stations[ST].platforms[ST-2]", "platform [700, 780) m is off the line (track L1"),
    "platform_shorter_than_the_train": (
        "from_m: 960, to_m: 1040, stops: {up: 1035}", "from_m: 1010, to_m: 1040, stops: {up: 1035}",
        "stations[ST].platforms[ST-1]", "platform of 30 m is shorter than the design train (40 m)"),
    "overlapping_platforms": (
        "points:\n",
        "  - name: ST2\n    platforms:\n"
        "      - {id: ST2-1, track: main, from_m: 1000, to_m: 1100, stops: {up: 1090}, "
        "fixed_block: true, setback: false}\npoints:\n",
        "stations[ST2].platforms[ST2-1]",
        "platform [1000, 1100) m overlaps stations[ST].platforms[ST-1] [960, 1040) m on track main"),
    "stop_inside_a_no_stop_section": (
        "{id: NS1, from_m: 1450, to_m: 1550,", "{id: NS1, from_m: 1000, to_m: 1100,",
        "stations[ST].platforms[ST-1]", "stops.up: stop point 1035 m lies inside no-stop section"),
    # radio
    "handover_not_at_a_cell_boundary": (
        "{id: H1, at_m: 1000}", "{id: H1, at_m: 1100}", "handovers[H1]",
        "handover at 1100 m is not at a boundary between two radio cells (boundaries at: 1000 m)"),
    "cell_boundary_without_handover": (
        "handovers:\n  - {id: H1, at_m: 1000}\n", "handovers: []\n",
        "radio_cells[C2]", "the cell boundary at 1000 m has no handover point"),
    "radio_cells_with_a_gap": (
        "{id: C2, from_m: 1000, to_m: 2000}", "{id: C2, from_m: 1200, to_m: 2000}",
        "radio_cells[C2]", "gap [1000, 1200) m after radio_cells[C1] not covered by radio cells"),
    # identifiers, kilometre posts, running lines, header
    "duplicate_id_across_sections": (
        "{id: LC1, at_m: 1500,", "{id: B2, at_m: 1500,", "level_crossings[B2]",
        "duplicate id 'B2' (first used by entry 2 of balises)"),
    "kilometre_posts_decreasing": (
        "{km: 11.0, at_m: 1000}", "{km: 9.5, at_m: 1000}", "kilometre_posts[1]",
        "kilometre posts must increase"),
    "kilometre_post_off_the_line": (
        "{km: 12.0, at_m: 2000}", "{km: 12.0, at_m: 2100}", "kilometre_posts[2]", "off the line"),
    "running_line_on_a_loop": (
        "{id: down, track: main,", "{id: down, track: L1,", "running_lines[down]",
        "running lines run on main tracks"),
    "name_not_the_file_name": (
        "name: mini_line", "name: other_line", "name", "must equal the file name 'mini_line'"),
    "source_without_citation": (
        "  - D5 §5.2\n", "  - the line plan\n", "source[0]", "cites no D1-D5 section"),
    "unknown_assumption": (
        "assumption: ASM-001", "assumption: ASM-099", "mini_line",
        "assumption: unknown assumption ASM-099"),
    # schema
    "missing_field": (
        "{id: B1, track: main, at_m: 50}", "{id: B1, at_m: 50}", "balises[B1]",
        "'track' is a required property"),
    "misspelt_field": (
        "{id: LC1, at_m: 1500,", "{id: LC1, at_km: 1.5,", "level_crossings[LC1]",
        "'at_m' is a required property"),
    "bad_route_position": (
        "points: P2, position: normal,", "points: P2, position: straight,",
        "routes[4]", "position: 'straight' is not one of"),
    "main_track_with_a_range": (
        "{id: main, kind: main}", "{id: main, kind: main, from_m: 0}", "tracks[main]",
        "from_m, to_m and points belong to loops"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_rule_violations_name_file_and_entry(line_spec, cli, tmp_path, case):
    old, new, entry, fragment = CASES[case]
    out = tmp_path / "out"
    r = cli("lines", "--spec", line_spec((old, new)), "--out", out)
    assert r.rc == 1
    assert r.has(MINI, entry, fragment), r.err
    assert r.lines[-1].startswith("lines: ") and "nothing written" in r.lines[-1]
    assert not out.exists()


# --------------------------------------------------------------------------- level crossings
# REQ-LC-016: every fault of the crossing data is an error naming file, crossing and reason.

LC1 = "{id: LC1, at_m: 1500, width_m: 8, warning_time_s: 30}"
LC_PARAMS = ("schema: railproof/parameters/1\narea: LC\nparameters:\n"
             "  - {id: default_warning_time_ms, value: 30000, unit: ms, source: ASM-001, "
             "requirements: [REQ-LC-002]}\n"
             "  - {id: min_warning_time_ms, value: 15000, unit: ms, source: ASM-001, "
             "requirements: [REQ-LC-016]}\n")


def _crossing_error(line_spec, cli, tmp_path, new, entry, fragment, extra=None):
    out = tmp_path / "out"
    r = cli("lines", "--spec", line_spec((LC1, new), extra=extra), "--out", out)
    assert r.rc == 1
    assert r.has(MINI, entry, fragment), r.err
    assert not out.exists()
    return r


# @verifies REQ-LC-016
def test_crossing_whose_width_reaches_beyond_the_line_end(line_spec, cli, tmp_path):
    # the centre lies on the line, the road does not: [1975, 2005) m
    _crossing_error(line_spec, cli, tmp_path,
                    "{id: LC1, at_m: 1990, width_m: 30, warning_time_s: 30}",
                    "level_crossings[LC1]",
                    "level crossing [1975, 2005) m (centre 1990 m, road width 30 m) is off the "
                    "line (0, 2000) m")


# @verifies REQ-LC-016
def test_crossing_reaching_the_line_start(line_spec, cli, tmp_path):
    _crossing_error(line_spec, cli, tmp_path, "{id: LC1, at_m: 3, width_m: 6, warning_time_s: 30}",
                    "level_crossings[LC1]", "level crossing [0, 6) m (centre 3 m, road width 6 m) "
                                            "is off the line")


# @verifies REQ-LC-016
@pytest.mark.parametrize("width", ["0", "-4"])
def test_crossing_width_not_positive(line_spec, cli, tmp_path, width):
    _crossing_error(line_spec, cli, tmp_path,
                    f"{{id: LC1, at_m: 1500, width_m: {width}, warning_time_s: 30}}",
                    "level_crossings[LC1]", f"road width {width} m is not positive")


# @verifies REQ-LC-016
@pytest.mark.parametrize("warn", ["0", "-30"])
def test_crossing_warning_time_not_positive(line_spec, cli, tmp_path, warn):
    _crossing_error(line_spec, cli, tmp_path,
                    f"{{id: LC1, at_m: 1500, width_m: 8, warning_time_s: {warn}}}",
                    "level_crossings[LC1]", f"design warning time {warn} s is not positive")


# @verifies REQ-LC-016
def test_crossing_warning_time_below_the_minimum(line_spec, cli, tmp_path):
    _crossing_error(line_spec, cli, tmp_path,
                    "{id: LC1, at_m: 1500, width_m: 8, warning_time_s: 14.999}",
                    "level_crossings[LC1]",
                    "design warning time 14.999 s is below min_warning_time_ms 15000 ms",
                    extra={"parameters/level_crossing.yaml": LC_PARAMS})


def _warning_ms(line_spec, cli, tmp_path, crossing, running_line):
    """The warning time in the line JSON of the crossing LC1, written as crossing, on the
    running line of that index (with the level-crossing parameters LC_PARAMS)."""
    spec = line_spec((LC1, crossing), extra={"parameters/level_crossing.yaml": LC_PARAMS})
    r = cli("lines", "--spec", spec, "--out", tmp_path / "out")
    assert r.rc == 0, r.err
    obj = json.loads((tmp_path / "out/mini_line.json").read_text())
    return obj["running_lines"][running_line]["level_crossings"][0]["warning_time_ms"]


# @verifies REQ-LC-016
def test_crossing_warning_time_at_the_minimum_is_accepted(line_spec, cli, tmp_path):
    crossing = "{id: LC1, at_m: 1500, width_m: 8, warning_time_s: 15}"
    assert _warning_ms(line_spec, cli, tmp_path, crossing, 0) == 15_000


# @verifies REQ-LC-016
def test_crossing_warning_time_not_whole_ms(line_spec, cli, tmp_path):
    _crossing_error(line_spec, cli, tmp_path,
                    "{id: LC1, at_m: 1500, width_m: 8, warning_time_s: 30.0005}",
                    "level_crossings[LC1]", "warning_time_s: 30.0005 is not a whole number of "
                                            "milliseconds")


# @verifies REQ-LC-016
def test_overlapping_crossings(line_spec, cli, tmp_path):
    _crossing_error(line_spec, cli, tmp_path,
                    LC1 + "\n  - {id: LC2, at_m: 1510, width_m: 14, warning_time_s: 30}",
                    "level_crossings[LC2]",
                    "level crossing [1503, 1517) m overlaps level_crossings[LC1] [1496, 1504) m")


# @verifies REQ-LC-016
def test_overlap_is_found_whatever_the_order(line_spec, cli, tmp_path):
    _crossing_error(line_spec, cli, tmp_path,
                    "{id: LC2, at_m: 1510, width_m: 14, warning_time_s: 30}\n  - " + LC1,
                    "level_crossings[LC2]", "overlaps level_crossings[LC1]")


def test_adjacent_crossings_do_not_overlap(line_spec, cli, tmp_path):
    spec = line_spec((LC1, LC1 + "\n  - {id: LC2, at_m: 1506, width_m: 4, warning_time_s: 30}"))
    r = cli("lines", "--spec", spec, "--out", tmp_path / "out")
    assert r.rc == 0, r.err  # [1496, 1504) and [1504, 1508) touch


def test_crossing_outside_every_no_stop_section(line_spec, cli, tmp_path):
    spec = line_spec(("{id: NS1, from_m: 1450, to_m: 1550,",
                      "{id: NS1, from_m: 1470, to_m: 1550,"))
    r = cli("lines", "--spec", spec, "--out", tmp_path / "out")
    assert r.rc == 1
    assert r.has(MINI, "level_crossings[LC1]",
                 "no no-stop section contains [1456, 1544) m (the crossing [1496, 1504) m widened "
                 "by the design train's 40 m on both sides)"), r.err


def test_crossing_width_rounded_outwards():
    assert lines.crossing_extent(1_500_000, 8_000) == (1_496_000, 1_504_000)
    assert lines.crossing_extent(1_500_000, 7_001) == (1_496_499, 1_503_501)
    # mirrored (length 2000 m): the same extent in running coordinates
    near, far = lines.crossing_extent(2_000_000 - 1_500_000, 7_001)
    assert (2_000_000 - far, 2_000_000 - near) == (1_496_499, 1_503_501)


def test_default_warning_time_from_the_parameters(line_spec, cli, tmp_path):
    assert _warning_ms(line_spec, cli, tmp_path, "{id: LC1, at_m: 1500, width_m: 8}", 1) == 30_000


def test_crossing_without_warning_time_and_without_default(line_spec, cli, tmp_path):
    _crossing_error(line_spec, cli, tmp_path, "{id: LC1, at_m: 1500, width_m: 8}",
                    "level_crossings[LC1]", "no warning_time_s and no default_warning_time_ms")


def test_crossing_without_width(line_spec, cli, tmp_path):
    _crossing_error(line_spec, cli, tmp_path, "{id: LC1, at_m: 1500, warning_time_s: 30}",
                    "level_crossings[LC1]", "'width_m' is a required property")


def test_provided_crossings_meet_the_parameters(tmp_path):
    from railproof_testgen import spec as spec_mod
    lc = spec_mod.load_parameters(REPO / "spec")["LC"]["parameters"]
    lines.generate(REPO / "spec", tmp_path)
    n = 0
    for name in PROVIDED:
        obj = json.loads((tmp_path / f"{name}.json").read_text())
        for rl in obj["running_lines"]:
            for c in rl["level_crossings"]:
                assert c["width_mm"] > 0
                assert c["warning_time_ms"] >= lc["min_warning_time_ms"]["value"]
                n += 1
    assert n == 2 * (3 + 12)  # d1: 3, d4: 12 crossings, each in both directions


def test_max_blocks_from_the_parameters(line_spec, cli, tmp_path):
    params = ("schema: railproof/parameters/1\narea: MB\nparameters:\n"
              "  - {id: max_blocks, value: 10, unit: blocks, source: ASM-001, "
              "requirements: [REQ-MB-021]}\n")
    spec = line_spec(extra={"parameters/moving_block.yaml": params})
    r = cli("lines", "--spec", spec, "--out", tmp_path / "out")
    assert r.rc == 1
    assert r.has(MINI, "tracks[main]", "20 virtual blocks exceed max_blocks 10"), r.err


def test_malformed_yaml(line_spec, cli, tmp_path):
    spec = line_spec(("length_m: 2000", "length_m: [2000"))
    r = cli("lines", "--spec", spec, "--out", tmp_path / "out")
    assert r.rc == 1
    assert r.has(MINI, "line", "malformed YAML"), r.err


def test_all_errors_are_collected(line_spec, cli, tmp_path):
    spec = line_spec(CASES["balise_off_the_line"][:2], CASES["unknown_points_in_a_route"][:2],
                     CASES["handover_not_at_a_cell_boundary"][:2])
    fails_with(cli("lines", "--spec", spec, "--out", tmp_path / "out"),
               (MINI, "balises[B2]", "off the line"), (MINI, "routes[1]", "unknown points 'P9'"),
               (MINI, "handovers[H1]", "not at a boundary"))


def test_nothing_written_if_any_line_is_invalid(line_spec, cli, tmp_path):
    spec = line_spec()
    broken = (spec / "lines/mini_line.yaml").read_text().replace(
        "name: mini_line", "name: broken_line").replace("{id: B2, track: main, at_m: 950}",
                                                        "{id: B2, track: main, at_m: 5000}")
    (spec / "lines/broken_line.yaml").write_text(broken)
    out = tmp_path / "out"
    out.mkdir()
    r = cli("lines", "--spec", spec, "--out", out)
    assert r.rc == 1
    assert r.has("lines/broken_line.yaml", "balises[B2]", "off the line"), r.err
    assert list(out.iterdir()) == []  # the valid mini_line.json is not written either
    with pytest.raises(SpecError) as exc:
        lines.generate(spec, out)
    assert exc.value.entry == "balises[B2]"
    assert list(out.iterdir()) == []


def test_no_line_files_is_an_error(tmp_path, cli):
    (tmp_path / "spec/lines").mkdir(parents=True)
    r = cli("lines", "--spec", tmp_path / "spec", "--out", tmp_path / "out")
    assert r.rc == 1
    assert r.has("spec/lines", "-", "no line files")


def test_validate_reports_line_errors(tree, cli):
    root = tree()
    text = (LINE_FIXTURES / "mini_line.yaml").read_text(encoding="utf-8")
    (root / "spec/lines").mkdir()
    (root / "spec/lines/mini_line.yaml").write_text(text, encoding="utf-8")
    r = cli("validate", "--spec", root / "spec")
    assert r.rc == 0, r.err
    assert "1 line(s)" in r.out
    (root / "spec/lines/mini_line.yaml").write_text(
        text.replace("{id: P1, track: main, from_m: 800,", "{id: P1, track: main, from_m: 790,")
            .replace("assumption: ASM-001", "assumption: ASM-077"), encoding="utf-8")
    r = cli("validate", "--spec", root / "spec")
    assert r.rc == 1
    assert r.has(MINI, "points[P1]", "span 2 virtual blocks"), r.err
    assert r.has(MINI, "mini_line", "assumption: unknown assumption ASM-077"), r.err
