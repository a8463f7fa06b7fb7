"""Hypothesis strategies and settings of the property-based tests of the spec checker and
the converters (test_input_properties.py, test_converter_properties.py).

Settings: a fixed number of examples, derived from a fixed seed (derandomize) so that a CI
run is repeatable and bounded, no deadline (the examples write and check small files), no
example database, and Hypothesis' caches in a temporary directory removed at the end. A
longer, randomised search runs with ``RAILPROOF_HYPOTHESIS=long`` (spec/design/data.md
§1.5).

Generators: JSON values within the loader's limits; valid documents of the three converted
kinds (a line built so that every topology rule holds, a train type satisfying REQ-BR-010,
a timetable on the D4 local line with the real train types); and for each kind the
single-field breaks that must be refused, with the entry the finding must name.
"""
from __future__ import annotations

import atexit
import copy
import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

import yaml
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from hypothesis.configuration import set_hypothesis_home_dir


# Hypothesis keeps caches (constants of the code, Unicode tables) in a directory of the
# working directory: here one of its own, removed when the tests end.
_HOME = tempfile.mkdtemp(prefix="railproof-hypothesis-")
set_hypothesis_home_dir(_HOME)
atexit.register(shutil.rmtree, _HOME, ignore_errors=True)

settings.register_profile(
    "ci", max_examples=30, deadline=None, derandomize=True, database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
settings.register_profile(
    "long", max_examples=3000, deadline=None, database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
settings.load_profile(os.environ.get("RAILPROOF_HYPOTHESIS", "ci"))

NAN = float("nan")


@contextmanager
def spec_tree(files=(), copies=()):
    """A temporary spec directory with the given files {relative path: text} and copies
    {relative path: source path}; removed afterwards (a fresh one per example)."""
    root = Path(tempfile.mkdtemp(prefix="railproof-prop-"))
    try:
        spec = root / "spec"
        for rel, src in dict(copies).items():
            (spec / rel).parent.mkdir(parents=True, exist_ok=True)
            if Path(src).is_dir():
                shutil.copytree(src, spec / rel, dirs_exist_ok=True)
            else:
                shutil.copy(src, spec / rel)
        for rel, text in dict(files).items():
            (spec / rel).parent.mkdir(parents=True, exist_ok=True)
            (spec / rel).write_text(text, encoding="utf-8")
        yield spec
    finally:
        shutil.rmtree(root, ignore_errors=True)


def dump(doc):
    """A document as YAML text (NaN and infinities as .nan and .inf)."""
    return yaml.safe_dump(doc, sort_keys=False, allow_unicode=True)


# --------------------------------------------------------------------------- JSON values

keys = st.text(st.characters(codec="utf-8", exclude_categories=("Cs",)), max_size=12)
scalars = (st.none() | st.booleans() | st.integers(-(1 << 70), 1 << 70)
           | st.floats(allow_nan=False, allow_infinity=False)
           | st.text(st.characters(codec="utf-8", exclude_categories=("Cs",)), max_size=20))
json_values = st.recursive(
    scalars, lambda inner: st.lists(inner, max_size=4) | st.dictionaries(keys, inner, max_size=4),
    max_leaves=20)
json_documents = st.dictionaries(keys, json_values, max_size=5)


def paths(doc, where=()):
    """Every path (tuple of keys and indices) to a value inside doc."""
    out = []
    items = (doc.items() if isinstance(doc, dict)
             else enumerate(doc) if isinstance(doc, list) else ())
    for k, v in items:
        out.append(where + (k,))
        out.extend(paths(v, where + (k,)))
    return out


def replaced(doc, path, value):
    """A deep copy of doc with the value at path replaced."""
    doc = copy.deepcopy(doc)
    node = doc
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value
    return doc


# --------------------------------------------------------------------------- lines

DESIGN_TRAIN_M = 40


@st.composite
def valid_lines(draw):
    """A line on which every rule of spec/lines/README.md holds by construction: one main
    track, both running lines, blocks of one length, gradients, speed limits and radio cells
    cut at block boundaries, a handover at every cell boundary, balises, curves, stations in
    the first half of the line and level crossings with their no-stop sections in the
    second."""
    block = draw(st.sampled_from([20, 50, 100]))
    nblocks = draw(st.integers(-(-600 // block), -(-600 // block) + 30))
    L = block * nblocks

    def cuts(max_size=4):
        inner = sorted(draw(st.sets(st.integers(1, nblocks - 1), max_size=max_size)))
        return [0] + [block * c for c in inner] + [L]

    def sections(points):
        return list(zip(points, points[1:]))

    km0 = draw(st.integers(-50_000, 50_000))  # metres of kilometrage at chainage 0
    doc = {
        "schema": "railproof/line/1", "name": "prop_line", "title": "Generated line",
        "source": ["D5 §5.2"], "assumption": "ASM-001", "length_m": L,
        "design_train": {"cars": 2, "length_m": DESIGN_TRAIN_M},
        "kilometre_posts": [{"km": km0 / 1000, "at_m": 0},
                            {"km": (km0 + draw(st.integers(1, 10_000))) / 1000, "at_m": L}],
        "tracks": [{"id": "main", "kind": "main"}],
        "running_lines": [{"id": "up", "track": "main", "direction": "increasing"},
                          {"id": "down", "track": "main", "direction": "decreasing"}],
        "virtual_blocks": [{"track": "main", "from_m": a, "to_m": b, "length_m": block}
                           for a, b in sections(cuts(2))],
        "gradients": [{"from_m": a, "to_m": b, "permille": draw(st.integers(-400, 400)) / 10}
                      for a, b in sections(cuts())],
        "speed_limits": [{"from_m": a, "to_m": b, "kmh": draw(st.integers(5, 360))}
                         for a, b in sections(cuts())],
        "balises": [{"id": f"B{i}", "track": "main", "at_m": at} for i, at in
                    enumerate(sorted(draw(st.sets(st.integers(1, L - 1), max_size=5))))],
        "stations": [],
        "radio_cells": [],
        "handovers": [],
    }
    if draw(st.booleans()):
        doc["running_lines"][0]["system_boundary_m"] = draw(st.integers(1, L - 1))
    curves = sections(cuts())
    doc["curves"] = [{"from_m": a, "to_m": b, "radius_m": draw(st.integers(50, 100_000))}
                     for a, b in curves if draw(st.booleans())]
    cells = sections(cuts())
    doc["radio_cells"] = [{"id": f"C{i}", "from_m": a, "to_m": b} for i, (a, b) in enumerate(cells)]
    doc["handovers"] = [{"id": f"H{i}", "at_m": a} for i, (a, _b) in enumerate(cells[1:])]
    # stations: 60 m platforms in 80 m slots of the first half; the up train stops at the
    # platform's far end, the down train at its near end
    slots = draw(st.sets(st.integers(0, (L // 2 - 60) // 80), max_size=2))
    for i, slot in enumerate(sorted(slots)):
        a = 80 * slot
        doc["stations"].append({"name": f"S{i}", "platforms": [{
            "id": f"S{i}-1", "track": "main", "from_m": a, "to_m": a + 60,
            "stops": {"up": a + 60, "down": a}, "fixed_block": draw(st.booleans()),
            "setback": draw(st.booleans())}]})
    # level crossings in the second half, each inside a no-stop section 100 m long
    centres = draw(st.sets(st.integers(0, (L // 2 - 120) // 110), max_size=2))
    doc["level_crossings"], doc["no_stop_sections"] = [], []
    for i, k in enumerate(sorted(centres)):
        c = L // 2 + 60 + 110 * k
        doc["level_crossings"].append({"id": f"LC{i}", "at_m": c,
                                       "width_m": draw(st.integers(4, 14)),
                                       "warning_time_s": draw(st.integers(15, 120))})
        doc["no_stop_sections"].append({"id": f"NS{i}", "from_m": c - 50, "to_m": c + 50,
                                        "reason": f"level crossing LC{i}"})
    return doc


def _entries(doc, section):
    """(entry name, path) of every item of a list of the document."""
    return [(f"{section}[{e.get('id', e.get('name', i))}]", (section, i))
            for i, e in enumerate(doc.get(section) or [])]


def line_breaks(doc):
    """(entry the finding must name, path, values each of which is refused) for the numeric
    fields of a line: out of range, not a number, not finite, or not a whole number of the
    unit the converter works in."""
    out = [("length_m", ("length_m",), [-5, 0, 1e7, "x", NAN, 100.0001])]
    for entry, p in _entries(doc, "balises"):
        out.append((entry, p + ("at_m",), [-1, 1e7, 0.0001, "x", NAN, doc["length_m"]]))
    for i in range(len(doc["gradients"])):
        out.append((f"gradients[{i}]", ("gradients", i, "permille"), [41, -41, 0.05, "x", NAN]))
    for i in range(len(doc["speed_limits"])):
        out.append((f"speed_limits[{i}]", ("speed_limits", i, "kmh"), [4, 361, 80.5, "x", True]))
    for i in range(len(doc["kilometre_posts"])):
        out.append((f"kilometre_posts[{i}]", ("kilometre_posts", i, "km"), [20_001, NAN, "x"]))
    for entry, p in _entries(doc, "radio_cells"):
        out.append((entry, p + ("to_m",), [-1, NAN, "x", 1e7]))
    for i in range(len(doc["curves"])):
        out.append((f"curves[{i}]", ("curves", i, "radius_m"), [49, 100_001, 300.5, 300.0]))
    for entry, p in _entries(doc, "level_crossings"):
        out.append((entry, p + ("width_m",), [0, -1, 101, NAN]))
        out.append((entry, p + ("warning_time_s",), [0, 601, NAN, 30.0001]))
    for entry, p in _entries(doc, "stations"):
        platform = doc["stations"][p[1]]["platforms"][0]["id"]
        out.append((f"{entry}.platforms[{platform}]", p + ("platforms", 0, "from_m"),
                    [-1, "x", 1e7, NAN]))
    return out


# --------------------------------------------------------------------------- trains

@st.composite
def valid_trains(draw):
    """A train type within its schema on which REQ-BR-010 holds: service pattern <=
    emergency pattern <= the lowest real emergency deceleration."""
    def rng(lo, hi):
        a = draw(st.integers(lo, hi))
        return [a, draw(st.integers(a, hi))]

    emergency = rng(1, 5000)
    e_pattern = draw(st.integers(1, emergency[0]))
    return {
        "schema": "railproof/train/1", "name": "prop_train", "title": "Generated train",
        "source": ["D1 §3 item 9"], "assumption": "ASM-024",
        "length_mm": draw(st.integers(1000, 1_000_000)),
        "max_speed_kmh": draw(st.integers(1, 300)),
        "accel_max_mm_s2": draw(st.integers(1, 5000)),
        "braking": {"emergency_pattern_mm_s2": e_pattern,
                    "service_pattern_mm_s2": draw(st.integers(1, e_pattern)),
                    "emergency_free_running_ms": rng(0, 60_000),
                    "service_free_running_ms": rng(0, 60_000),
                    "emergency_overspeed_kmh": draw(st.integers(0, 30))},
        "supervision": {"speed_error_ppm": draw(st.integers(0, 100_000)),
                        "speed_error_abs_mm_s": draw(st.integers(0, 10_000))},
        "uncertainty": {"emergency_deceleration_mm_s2": emergency,
                        "service_deceleration_mm_s2": rng(1, 5000),
                        "odometry_ppm": draw(st.integers(0, 100_000)),
                        "readhesion_margin_mm": draw(st.integers(0, 1_000_000))},
    }


# (group or None, key, lowest, highest) of every integer of a train type
TRAIN_INTEGERS = [(None, "length_mm", 1000, 1_000_000), (None, "max_speed_kmh", 1, 300),
                  (None, "accel_max_mm_s2", 1, 5000),
                  ("braking", "emergency_pattern_mm_s2", 1, 5000),
                  ("braking", "service_pattern_mm_s2", 1, 5000),
                  ("braking", "emergency_overspeed_kmh", 0, 30),
                  ("supervision", "speed_error_ppm", 0, 100_000),
                  ("supervision", "speed_error_abs_mm_s", 0, 10_000),
                  ("uncertainty", "odometry_ppm", 0, 100_000),
                  ("uncertainty", "readhesion_margin_mm", 0, 1_000_000)]


def train_breaks(doc):
    """(entry, path, refused values) of a train type's integers and ranges."""
    out = []
    for group, key, lo, hi in TRAIN_INTEGERS:
        out.append((group or key, (group, key) if group else (key,),
                    [lo - 1, hi + 1, lo + 0.5, float(lo), "x", NAN, True]))
    for group, key in (("braking", "emergency_free_running_ms"),
                       ("braking", "service_free_running_ms")):
        lo, hi = doc[group][key]
        out.append((f"{group}.{key}" if hi < 60_000 else group, (group, key),
                    [[hi + 1, hi] if hi < 60_000 else [0, 60_001]]))
    return out


# --------------------------------------------------------------------------- timetables

# The D4 local line's running lines and their stations in running order, and the train
# types that fit its platforms (those of the real timetable).
D4_STATIONS = {"up": ["S1", "S2", "S3", "S4", "S5"], "down": ["S5", "S4", "S3", "S2", "S1"]}
D4_TRAINS = ["dmu2_d4", "emu3_d1"]


def clock(seconds):
    return f"{seconds // 3600:02d}:{seconds // 60 % 60:02d}:{seconds % 60:02d}"


@st.composite
def valid_timetables(draw):
    """A timetable of the D4 local line that every rule of spec/timetables/README.md
    accepts: services in order of departure, stops between origin and destination in
    running order, every dwell at least the minimum."""
    def pair(lo, hi):
        a = draw(st.integers(lo, hi))
        return [a, draw(st.integers(a, hi))]

    min_dwell = draw(st.integers(0, 60))
    doc = {
        "schema": "railproof/timetable/1", "name": "d4_local_line", "line": "d4_local_line",
        "title": "Generated timetable", "source": ["D5 §5.3"],
        "seed": draw(st.integers(0, 1 << 53)),
        "running_time_allowance_percent": draw(st.integers(0, 100)),
        "planned_time_step_s": draw(st.integers(1, 300)),
        "driver": {"cruise_percent": pair(50, 100), "start_delay_s": pair(0, 600),
                   "min_dwell_s": min_dwell},
        "communication": {"uplink_ms": pair(0, 60_000), "downlink_ms": pair(0, 60_000),
                          "ground_cycle_ms": draw(st.integers(1, 10_000)),
                          "onboard_cycle_ms": draw(st.integers(1, 10_000)),
                          "barrier_travel_s": pair(0, 60),
                          "report_latency_ms": pair(0, 60_000),
                          "onboard_clock_error_ms": draw(st.integers(0, 10_000)),
                          "gnss_clock_error_ms": draw(st.integers(0, 10_000))},
        "services": [],
    }
    t = draw(st.integers(0, 20 * 3600))
    for i in range(draw(st.integers(1, 6))):
        rl = draw(st.sampled_from(sorted(D4_STATIONS)))
        names = D4_STATIONS[rl]
        first = draw(st.integers(0, len(names) - 2))
        last = draw(st.integers(first + 1, len(names) - 1))
        stops = [names[k] for k in sorted(draw(st.sets(st.integers(first + 1, last - 1)))
                                          if last - first > 1 else [])]
        t += draw(st.integers(1, 3600))
        sv = {"id": f"T{i}", "train": draw(st.sampled_from(D4_TRAINS)), "running_line": rl,
              "depart": clock(t), "stops": stops}
        if first:
            sv["from"] = names[first]
        if last != len(names) - 1:
            sv["to"] = names[last]
        if stops:
            dwell = draw(st.integers(min_dwell, 3600))
            sv["dwell_s"] = dwell if draw(st.booleans()) else {"default": dwell}
        doc["services"].append(sv)
    return doc


def timetable_breaks(doc):
    """(entry, path, refused values) of a timetable."""
    out = [("seed", ("seed",), [-1, 1.5, "x", (1 << 53) + 1]),
           ("planned_time_step_s", ("planned_time_step_s",), [0.5, 301, NAN, "x"]),
           ("driver", ("driver", "min_dwell_s"), [-1, 3601, NAN]),
           ("driver", ("driver", "cruise_percent"), [[49, 100], [100, 50], [50.5, 60]]),
           ("communication", ("communication", "ground_cycle_ms"), [0, 10_001, 5.5]),
           ("communication", ("communication", "uplink_ms"), [[0, 60_001], [5, 4]])]
    for i, sv in enumerate(doc["services"]):
        entry = f"services[{sv['id']}]"
        out.append((entry, ("services", i, "depart"), ["48:00", "6:00", 360, ""]))
        out.append((entry, ("services", i, "train"), ["no_such_train", 5]))
        out.append((entry, ("services", i, "running_line"), ["sideways"]))
        out.append((entry, ("services", i, "stops"), [["SX"], [1], "S2"]))
        if sv["stops"]:
            low = doc["driver"]["min_dwell_s"] - 1
            out.append((entry, ("services", i, "dwell_s"),
                        [-1, 3601, NAN] + ([low] if low >= 0 else [])))
    return out
