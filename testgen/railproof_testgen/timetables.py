"""Timetables: validation of spec/timetables/*.yaml and generation of the timetable JSON.

Command ``timetables --spec DIR --out DIR`` checks every ``spec/timetables/*.yaml`` against
``spec/schemas/timetable.schema.json`` (Draft 2020-12) and the rules below, then writes
``OUT/<name>.json`` (schema ``railproof/timetable-json/1``, read by the C++ warning-time
study, spec/timetables/README.md): every time in integer milliseconds, every stop with its
own dwell. Every finding is one line ``file: entry: reason``; with any error nothing is
written and the exit status is 1. ``validate --spec`` runs the same checks.

Rules after the schema (entries such as ``services[R105].stops[0]``):
- ``name`` is the file name; every source cites D1-D5 §, an ASM or a standard; the
  assumptions named exist;
- every time given in seconds is a whole number of milliseconds; every range
  ``[min, max]`` has min <= max;
- ``line`` names a valid line of spec/lines; each service's ``train`` a train type of
  spec/trains and its ``running_line`` a running line of that line;
- service ids are unique; origin (``from``, default the first station of the running
  line) and destination (``to``, default the last) are stations of the running line, the
  origin before the destination; the stops are stations of the running line, strictly
  between origin and destination, in running order;
- every stop has a dwell (``dwell_s`` a number, or a mapping station -> seconds with an
  optional ``default``; a mapping key that is neither ``default`` nor a stop is an error)
  of at least ``driver.min_dwell_s``;
- the train fits every platform it starts, stops or ends at (front at the stop point,
  rear on the platform);
- the departures of one running line from one origin increase strictly, in file order.
"""
from __future__ import annotations

from decimal import Decimal
from pathlib import Path

from . import SPEC_DIR, add_command
from . import spec as spec_mod
from . import checks

SUB = "timetables"
SCHEMA_FILE = "timetable.schema.json"
JSON_SCHEMA = "railproof/timetable-json/1"
DEFAULT_PLANNED_TIME_STEP_S = 5


def clock_ms(text):
    """"HH:MM" or "HH:MM:SS" (the schema's pattern) -> ms after midnight."""
    parts = [int(p) for p in text.split(":")]
    h, m, s = (parts + [0])[:3]
    return ((h * 60 + m) * 60 + s) * 1000


def _clock(ms):
    s = ms // 1000
    return f"{s // 3600:02d}:{s // 60 % 60:02d}:{s % 60:02d}"


class _Timetable:
    """Semantic checks and conversion of one schema-valid timetable file."""

    def __init__(self, spec_dir, path, data, report, lines, trains):
        self.spec_dir, self.f, self.d, self.report = spec_dir, path, data, report
        self.lines, self.trains = lines, trains
        self.stations = {}  # running line id -> (station names, name -> index, their listing)
        self.ok = True

    def err(self, entry, reason):
        self.report.error(self.f, entry, reason)
        self.ok = False

    def ms(self, entry, seconds):
        """Seconds -> whole milliseconds, or None (reported)."""
        v = Decimal(str(seconds)) * 1000
        if v != v.to_integral_value():
            self.err(entry, f"{seconds} s is not a whole number of milliseconds")
            return None
        return int(v)

    def pair(self, entry, values, unit, scale_ms=None):
        """[min, max] (converted to ms if scale_ms) with min <= max, or None (reported)."""
        lo, hi = values
        if lo > hi:
            self.err(entry, f"min {lo} {unit} is greater than max {hi} {unit}")
            return None
        if scale_ms:
            lo, hi = self.ms(entry, lo), self.ms(entry, hi)
            return None if lo is None or hi is None else [lo, hi]
        return [lo, hi]

    def check(self):
        d, f = self.d, self.f
        if d["name"] != f.stem:
            self.err("name", f"{d['name']!r} must equal the file name {f.stem!r}")
        if not checks.check_sources(self.report, f, d["name"], d["source"]):
            self.ok = False
        step = self.ms("planned_time_step_s", d.get("planned_time_step_s",
                                                   DEFAULT_PLANNED_TIME_STEP_S))
        dr, cm = d["driver"], d["communication"]
        driver = {
            "cruise_percent": self.pair("driver.cruise_percent", dr["cruise_percent"], "%"),
            "start_delay_ms": self.pair("driver.start_delay_s", dr["start_delay_s"], "s", True),
            "min_dwell_ms": self.ms("driver.min_dwell_s", dr["min_dwell_s"]),
        }
        comms = {k: self.pair(f"communication.{k}", cm[k], "ms")
                 for k in ("uplink_ms", "downlink_ms", "report_latency_ms")}
        comms["barrier_travel_ms"] = self.pair("communication.barrier_travel_s",
                                               cm["barrier_travel_s"], "s", True)
        comms.update({k: cm[k] for k in ("ground_cycle_ms", "onboard_cycle_ms",
                                         "onboard_clock_error_ms", "gnss_clock_error_ms")})
        line = self._line()
        services = self._services(line, driver["min_dwell_ms"])
        if not self.ok:
            return None
        obj = {
            "schema": JSON_SCHEMA,
            "name": d["name"],
            "line": d["line"],
            "title": d["title"],
            "source": list(d["source"]),
            "seed": d["seed"],
            "running_time_allowance_percent": d["running_time_allowance_percent"],
            "planned_time_step_ms": step,
            "driver": driver,
            "communication": comms,
            "services": services,
        }
        obj.update({k: d[k] for k in ("assumption", "note") if k in d})
        return obj

    def _line(self):
        line = self.lines.get(self.d["line"])
        if line is None:
            self.err("line", checks.missing_data(self.spec_dir, "lines", self.d["line"], "line"))
        return line

    def _services(self, line, min_dwell_ms):
        out, ids, last_departure = [], {}, {}
        rls = {}  # the line's running lines by id (the first of an id), looked up per service
        for r in (line or {}).get("running_lines", []):
            rls.setdefault(r["id"], r)
        listed = checks.listing(rls)
        for i, sv in enumerate(self.d["services"]):
            entry = checks.label("services", sv, i)
            if sv["id"] in ids:
                self.err(entry, f"id: duplicate service id {sv['id']!r} (first used by "
                                f"services[{ids[sv['id']]}])")
            ids.setdefault(sv["id"], i)
            train = self.trains.get(sv["train"])
            if train is None:
                self.err(f"{entry}.train", checks.missing_data(self.spec_dir, "trains",
                                                             sv["train"], "train type"))
            stops = self._stops(entry, sv, min_dwell_ms)
            depart = clock_ms(sv["depart"])
            item = {"id": sv["id"], "train": sv["train"], "running_line": sv["running_line"],
                    "depart_ms": depart, "stops": stops}
            item.update({k: sv[k] for k in ("from", "to", "note") if k in sv})
            out.append(item)
            if line is None:
                continue
            rl = rls.get(sv["running_line"])
            if rl is None:
                self.err(f"{entry}.running_line", f"unknown running line {sv['running_line']!r} "
                         f"of line {line['name']} (has: {listed})")
                continue
            origin = self._route(entry, sv, rl, train)
            if origin is None:
                continue
            key = (rl["id"], origin)
            prev = last_departure.get(key)
            if prev is not None and depart <= prev[0]:
                self.err(f"{entry}.depart", f"departure {_clock(depart)} is not after the "
                         f"departure {_clock(prev[0])} of {prev[1]} from {origin} on running "
                         f"line {rl['id']} (services in order of departure)")
            last_departure[key] = (depart, entry)
        return out

    def _stops(self, entry, sv, min_dwell_ms):
        """[{station, dwell_ms}] of a service's stops (each with its dwell, checked)."""
        dwell = sv.get("dwell_s")
        by_station = dwell if isinstance(dwell, dict) else {}
        default = dwell if not isinstance(dwell, dict) else dwell.get("default")
        stops = set(sv["stops"])
        for k in by_station:
            if k != "default" and k not in stops:
                self.err(f"{entry}.dwell_s", f"dwell for {k!r}, which is not one of the stops")
        out = []
        for k, station in enumerate(sv["stops"]):
            where = f"{entry}.stops[{k}]"
            seconds = by_station.get(station, default)
            if seconds is None:
                self.err(where, f"no dwell for the stop at {station!r} (give dwell_s as a "
                                "number or with 'default')")
                continue
            ms = self.ms(where, seconds)
            if ms is not None and min_dwell_ms is not None and ms < min_dwell_ms:
                self.err(where, f"dwell {seconds} s at {station} is below the minimum dwell "
                                f"{min_dwell_ms / 1000:g} s (driver.min_dwell_s)")
            out.append({"station": station, "dwell_ms": ms})
        return out

    def _route(self, entry, sv, rl, train):
        """Stations of the service on running line rl checked; returns the origin's name,
        or None if a station is unknown."""
        if rl["id"] not in self.stations:
            names = [s["name"] for s in rl["stations"]]
            at = {}
            for i, name in enumerate(names):
                at.setdefault(name, i)
            self.stations[rl["id"]] = names, at, checks.listing(names)
        names, at, listed = self.stations[rl["id"]]
        if len(names) < 2:
            self.err(f"{entry}.running_line", f"running line {rl['id']} has fewer than two "
                                              "stations")
            return None

        def index(field, name):
            if name in at:
                return at[name]
            self.err(f"{entry}.{field}", f"station {name!r} has no stop on running line "
                                         f"{rl['id']} (stops: {listed})")
            return None

        first = index("from", sv["from"]) if "from" in sv else 0
        last = index("to", sv["to"]) if "to" in sv else len(names) - 1
        calls = [index(f"stops[{k}]", s) for k, s in enumerate(sv["stops"])]
        if first is None or last is None or None in calls:
            return None
        if first >= last:
            self.err(entry, f"origin {names[first]} is not before destination {names[last]} "
                            f"on running line {rl['id']}")
            return None
        prev = first
        for k, idx in enumerate(calls):
            where = f"{entry}.stops[{k}]"
            if not first < idx < last:
                self.err(where, f"stop at {names[idx]} is not between the origin {names[first]} "
                                f"and the destination {names[last]}")
            elif idx <= prev:
                self.err(where, f"stop at {names[idx]} is not in running order (after "
                                f"{names[prev]})")
            prev = max(prev, idx)
        if train is not None:
            for field, idx in [("from", first), ("to", last)] + \
                    [(f"stops[{k}]", idx) for k, idx in enumerate(calls)]:
                st = rl["stations"][idx]
                if st["stop_mm"] - train["length_mm"] < st["platform_begin_mm"]:
                    self.err(f"{entry}.{field}", f"train {train['name']} "
                             f"({train['length_mm'] / 1000:g} m) does not fit platform "
                             f"{st['name']} [{st['platform_begin_mm']}, "
                             f"{st['platform_end_mm']}) mm with its front at the stop "
                             f"{st['stop_mm']} mm")
        return names[first]


def timetable_files(spec_dir):
    return spec_mod.spec_files(spec_dir, SUB)


def check_timetables(spec_dir, report, lines, trains):
    """Check every spec/timetables/*.yaml into `report` against `lines` (name -> line JSON
    object) and `trains` (name -> train JSON object). Returns (outputs, refs): outputs
    maps name -> timetable JSON object of the files without errors; refs are the
    assumption and source strings for the caller's reference check."""
    spec_dir = Path(spec_dir)
    outputs, refs = {}, []

    def check(f, data):
        refs.extend(checks.provenance_refs(f, data["name"], data))
        obj = _Timetable(spec_dir, f, data, report, lines, trains).check()
        if obj is not None:
            outputs[data["name"]] = obj

    checks.check_data_files(spec_dir, timetable_files(spec_dir), SCHEMA_FILE, report, check)
    return outputs, refs


def build(spec_dir):
    """(outputs, report): every timetable checked against the valid lines and train types
    of spec_dir (their own errors are reported by the lines and trains steps)."""
    from . import lines as lines_mod
    from . import trains as trains_mod
    report = checks.Report()
    spec_dir = Path(spec_dir)
    if not timetable_files(spec_dir):
        report.error(spec_dir / SUB, "-", "no timetable files (*.yaml)")
        return {}, report
    others = checks.Report()  # the lines' and trains' own findings belong to their steps
    lines, _ = lines_mod.check_lines(spec_dir, others)
    trains, _ = trains_mod.check_trains(spec_dir, others)
    outputs, refs = check_timetables(spec_dir, report, lines,
                                     {n: t for (m, n), t in trains.items() if not m})
    checks.check_assumption_refs(spec_dir, refs, report)
    return outputs, report


def _converted(name, obj, path):
    return f"{name}: {len(obj['services'])} services on line {obj['line']} -> {path}"


def run(args):
    return checks.convert(SUB, args, build, _converted)


def register(sub):
    add_command(sub, "timetables", run, "validate spec/timetables and write the timetable JSON",
                """Check every spec/timetables/*.yaml against spec/schemas/timetable.schema.json
                and the rules of spec/timetables/README.md (stations on the running line in
                running order, known train types, dwell times, platforms, departures in
                order), then write OUT/<name>.json (schema railproof/timetable-json/1, times in
                ms). Prints every finding as 'file: entry: reason'; on any error nothing is
                written and the exit status is 1.""",
                spec=SPEC_DIR, out="output directory (build/gen/timetables)")
