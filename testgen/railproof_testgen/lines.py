"""Line data: validation of spec/lines/*.yaml and generation of the line JSON.

Command ``lines --spec DIR --out DIR`` checks every ``spec/lines/*.yaml`` against
``spec/schemas/line.schema.json`` (Draft 2020-12) and the topology rules below, then
writes ``OUT/<name>.json`` (schema ``railproof/line-json/1``, the contract with the C++
line loader, spec/lines/README.md).  Every finding is one line ``file: entry: reason``;
if any line file has an error, nothing is written and the exit status is 1.
``validate --spec`` runs the same checks (REQ-MB-020).

A line is described once in line chainage (metres from the line origin).  Each running
line is one direction of one main track: running position = chainage (direction
``increasing``) or ``length - chainage`` (``decreasing``); sections are mirrored and
gradients change sign.  Output values are integers: mm, km/h, permille x 10, metres of
curve radius.

Rules after the schema (entry names such as ``balises[B7]`` or ``gradients[3]``):
- ``name`` is the file name; every source cites D1-D5 §, an ASM or a standard; the
  ``assumption`` exists (checked with the assumptions of spec/assumptions);
- every length and position is a whole number of mm, every gradient a whole number of
  0.1 permille, every kilometre post a whole number of mm;
- identifiers are unique: tracks, running lines, routes each in their own namespace;
  balises, points, level crossings, radio cells, handovers, platforms, no-stop sections
  and station names share one;
- kilometre posts lie on the line, with chainage and kilometrage strictly increasing;
- main tracks span [0, length); a loop lies inside the line between its two points,
  which lie on one main track and lead (reverse) to the loop;
- running lines run on main tracks; a system boundary lies strictly inside the line;
- virtual blocks of each track: entries in increasing order, each non-empty, an exact
  multiple of its ``length_m``, contiguous and covering the track exactly (an overlap or a
  gap names both entries); every track has blocks; at most ``max_blocks`` per track;
- gradients, speed limits and radio cells cover [0, length) without gap or overlap
  (entries in increasing order);
- curves and no-stop sections lie on the line, in increasing order, not overlapping;
- balises lie strictly inside their track;
- level crossings (REQ-LC-016): road width and design warning time positive, the warning
  time at least ``min_warning_time_ms`` (spec/parameters, area LC); the crossing's extent
  ``[at - width/2, at + width/2)`` (rounded outwards to whole mm) strictly inside the line;
  no two crossings overlap; a train of the design length standing with any part on the
  crossing stands in a no-stop section (the extent widened by the design train's length
  on both sides lies inside one no-stop section);
- points lie on their track and inside exactly one virtual block (none: "point without a
  virtual block"; several: named), no two points share a block, ``reverse_to`` is another
  existing track;
- routes name an existing running line and existing points on its track, lie on the line,
  run in the running line's direction and contain the points' virtual block;
- platforms lie on their track, are at least as long as the design train, do not overlap
  another platform of the same track; each stop names a running line that can reach the
  platform (its own track, or a loop of it), lies within the platform for that running
  direction (front at most at the platform's far end) and outside every no-stop section;
  a station has at most one stop per running line, and no two stations the same stop;
- every boundary between two radio cells has exactly one handover, and every handover is
  at such a boundary.
"""
from __future__ import annotations

import bisect
from decimal import Decimal, InvalidOperation
from pathlib import Path

from . import SPEC_DIR, add_command
from . import spec as spec_mod
from .files import write_all
from . import checks
from .errors import SpecError
from .checks import label as _label

SUB = "lines"
SCHEMA_FILE = "line.schema.json"
JSON_SCHEMA = "railproof/line-json/1"

# Sections whose ids share one namespace within a line file.
_LOCATED = ("balises", "points", "level_crossings", "radio_cells", "handovers",
            "no_stop_sections")


# --------------------------------------------------------------------------- helpers

def _m(mm):
    """mm -> human metres for messages ('14500', '12.5')."""
    if mm % 1000 == 0:
        return str(mm // 1000)
    return f"{mm / 1000:.3f}".rstrip("0")


def _sec(a, b):
    return f"[{_m(a)}, {_m(b)}) m"


def _int_parameter(spec_dir, area, pid):
    """Integer parameter `pid` of `area` in spec/parameters, or None if not available."""
    try:
        params = spec_mod.load_parameters(spec_dir)
    except SpecError:
        return None
    e = params.get(area, {}).get("parameters", {}).get(pid)
    return int(e["value"]) if e and isinstance(e.get("value"), int) else None


def _max_blocks(spec_dir):
    """max_blocks of spec/parameters (MB), or None if not available."""
    return _int_parameter(spec_dir, "MB", "max_blocks")


class _CrossingLimits:
    """Level-crossing parameters of spec/parameters (LC), each None if not available:
    ``min_warning_ms`` (lowest design warning time accepted) and ``default_warning_ms``
    (the design warning time of a crossing that states none)."""

    def __init__(self, min_warning_ms=None, default_warning_ms=None):
        self.min_warning_ms, self.default_warning_ms = min_warning_ms, default_warning_ms

    @classmethod
    def from_spec(cls, spec_dir):
        return cls(_int_parameter(spec_dir, "LC", "min_warning_time_ms"),
                   _int_parameter(spec_dir, "LC", "default_warning_time_ms"))


# The count of virtual blocks of a track when spec/parameters gives no max_blocks (a spec
# tree without parameters, as the tests' miniature lines): the largest value the parameter
# schema admits for a count (spec/schemas/parameters.schema.json, $defs/count).
BLOCKS_LIMIT = 1 << 20


def _overlapping(blocks, a, b, disjoint):
    """The blocks of a track's sorted list that overlap [a, b). Where the blocks do not
    overlap each other (disjoint: every valid track) the first is found by bisection: a
    lookup does not walk the track."""
    if not disjoint:  # overlapping blocks, reported already
        return [blk for blk in blocks if blk[0] < b and a < blk[1]]
    k = max(bisect.bisect_right(blocks, (a, float("inf"))) - 1, 0)
    out = []
    while k < len(blocks) and blocks[k][0] < b:
        if a < blocks[k][1]:
            out.append(blocks[k])
        k += 1
    return out


class _Sections:
    """Sections (entry, (a, b), id) of a line in mm, [a, b): the ones holding a point or a
    range. Where they do not overlap (every valid line) the one is found by bisection, so
    that checking every stop or crossing against them does not walk them all each time."""

    def __init__(self, items):
        self.items = sorted(items, key=lambda x: x[1])
        self.starts = [r[0] for _, r, _ in self.items]
        self.disjoint = all(x[1][1] <= y[1][0] for x, y in zip(self.items, self.items[1:]))

    def at(self, x, increasing):
        """The sections a point x lies in: a <= x < b, or for the decreasing direction (in
        which a section runs from b down to a) a < x <= b."""
        if not self.disjoint:
            return [s for s in self.items
                    if (s[1][0] <= x < s[1][1] if increasing else s[1][0] < x <= s[1][1])]
        k = (bisect.bisect_right if increasing else bisect.bisect_left)(self.starts, x) - 1
        if k < 0:
            return []
        a, b = self.items[k][1]
        return [self.items[k]] if (x < b if increasing else x <= b) else []

    def containing(self, a, b):
        """The sections that contain [a, b]."""
        if not self.disjoint:
            return [s for s in self.items if s[1][0] <= a and b <= s[1][1]]
        k = bisect.bisect_right(self.starts, a) - 1
        return [self.items[k]] if k >= 0 and b <= self.items[k][1][1] else []


def crossing_extent(at_mm, width_mm):
    """[near, far) of a crossing in mm, rounded outwards (spec/design/lc.md §1):
    at - ceil(width/2), at + ceil(width/2); symmetric, so mirroring keeps it exact."""
    half = (width_mm + 1) // 2
    return at_mm - half, at_mm + half


# --------------------------------------------------------------------------- checker

class _Line:
    """Semantic checks and conversion of one schema-valid line file."""

    def __init__(self, path, data, report, max_blocks, lc_limits=None):
        self.f, self.d, self.report, self.max_blocks = path, data, report, max_blocks
        self.lc = lc_limits if lc_limits is not None else _CrossingLimits()
        self.ok = True

    def err(self, entry, reason):
        self.report.error(self.f, entry, reason)
        self.ok = False

    # ---- units
    def _scaled(self, entry, field, value, scale, what):
        try:
            v = Decimal(str(value)) * scale
        except InvalidOperation:  # pragma: no cover - the schema admits only numbers
            self.err(entry, f"{field}: {value!r} is not a number")
            return None
        if v != v.to_integral_value():
            self.err(entry, f"{field}: {value} is not a whole number of {what}")
            return None
        return int(v)

    def mm(self, entry, field, value):
        return self._scaled(entry, field, value, 1000, "millimetres")

    def _range(self, entry, item, lo_key="from_m", hi_key="to_m"):
        """(a, b) in mm with a < b, or None (reported)."""
        a = self.mm(entry, lo_key, item[lo_key])
        b = self.mm(entry, hi_key, item[hi_key])
        if a is None or b is None:
            return None
        if a >= b:
            self.err(entry, f"empty or reversed range: {lo_key} {_m(a)} m is not below "
                            f"{hi_key} {_m(b)} m")
            return None
        return a, b

    def _range_on_track(self, entry, item, track, what, verb):
        """The range of an item on a track (points, a platform) as _range, or None (reported,
        or not judged while the track's own range is invalid): it must lie on the track."""
        r = self._range(entry, item)
        if r is None or track["range"] is None:
            return None
        lo, hi = track["range"]
        if r[0] < lo or r[1] > hi:
            self.err(entry, f"{what} {_sec(*r)} {verb} off the line (track {item['track']} "
                            f"{_sec(lo, hi)})")
            return None
        return r

    # ---- coverage helpers
    def _cover(self, section, items, lo, hi, what):
        """Entries (entry, (a, b)) in order must tile [lo, hi) exactly.  An entry whose
        range was rejected (None) was reported already: coverage is then not judged."""
        if any(r is None for _, r in items):
            return
        if not items:
            self.err(section, f"{what} must cover {_sec(lo, hi)}: none given")
            return
        expect, prev = lo, None
        for entry, (a, b) in items:
            if a < expect:
                if prev is None:
                    self.err(entry, f"begins at {_m(a)} m, before the start {_m(lo)} m")
                else:
                    self.err(entry, f"overlaps {prev} ({what} must not overlap: begins at "
                                    f"{_m(a)} m, {prev} ends at {_m(expect)} m)")
            elif a > expect:
                if prev is None:
                    self.err(entry, f"begins at {_m(a)} m: gap {_sec(expect, a)} not covered "
                                    f"by {what} (must begin at {_m(lo)} m)")
                else:
                    self.err(entry, f"gap {_sec(expect, a)} after {prev} not covered by {what}")
            expect, prev = max(expect, b), entry
        if expect < hi:
            self.err(prev, f"{what} end at {_m(expect)} m: gap {_sec(expect, hi)} not covered "
                           f"(must end at {_m(hi)} m)")
        elif expect > hi:
            self.err(prev, f"ends at {_m(expect)} m, beyond the end {_m(hi)} m")

    def _disjoint(self, items, lo, hi, what):
        """Entries (entry, (a, b)) inside [lo, hi], in increasing order, not overlapping."""
        prev = None
        for entry, (a, b) in items:
            if a < lo or b > hi:
                self.err(entry, f"{_sec(a, b)} is off the line {_sec(lo, hi)}")
            if prev is not None:
                pe, (pa, pb) = prev
                if a < pb:
                    self.err(entry, f"{_sec(a, b)} overlaps {pe} {_sec(pa, pb)} or is out of "
                                    f"order ({what} must be in increasing order, not overlapping)")
            prev = (entry, (a, b))

    # ---- main check
    def check(self):
        """The rules of the README, one group after another (a group may skip what an earlier
        one rejected: one fault, one message); the line JSON object, or None."""
        d = self.d
        f = self.f
        if d["name"] != f.stem:
            self.err("name", f"{d['name']!r} must equal the file name {f.stem!r}")
        for i, s in enumerate(d["source"]):
            if not checks.CITATION.search(s):
                self.err(f"source[{i}]", f"{s!r} cites no D1-D5 section, ASM-NNN or named "
                                         "standard")
        L = self.mm("length_m", "length_m", d["length_m"])
        if L is None:
            return None
        self.L = L
        train_mm = self.mm("design_train", "length_m", d["design_train"]["length_m"])

        self._check_identifiers()
        kmp = self._kilometre_posts()
        tracks = self._tracks()
        rlines = self._running_lines(tracks)
        self._virtual_blocks(tracks)
        grads, speeds, curves = self._profile()
        nostop = self._no_stop_sections()
        balises = self._balises(tracks)
        lcs = self._level_crossings(L, train_mm, nostop)
        declared, points = self._points(tracks)
        self._loops(tracks, declared, points)
        routes = self._routes(rlines, declared, points)
        stations = self._stations(tracks, rlines, nostop, train_mm)
        cells, handovers = self._radio()
        if not self.ok:
            return None
        return self._emit(kmp, rlines, grads, speeds, curves, balises, stations, points,
                          routes, lcs, cells, handovers, nostop, train_mm)

    # ---- rule groups, in the order of the README
    def _check_identifiers(self):
        """Identifiers are unique: balises, points, level crossings, radio cells, handovers,
        no-stop sections, stations and platforms share one namespace; tracks, running lines and
        routes each have their own."""
        d = self.d
        seen = {}
        for section in _LOCATED:
            for i, item in enumerate(d.get(section) or []):
                self._unique(seen, item["id"], _label(section, item, i),
                             f"entry {i + 1} of {section}")
        for i, st in enumerate(d["stations"]):
            self._unique(seen, st["name"], _label("stations", st, i), f"station {i + 1}")
            for j, p in enumerate(st["platforms"]):
                self._unique(seen, p["id"], f"{_label('stations', st, i)}."
                                            f"{_label('platforms', p, j)}",
                             f"platform {j + 1} of station {i + 1}")
        for section in ("tracks", "running_lines", "routes"):
            own = {}
            for i, item in enumerate(d.get(section) or []):
                self._unique(own, item["id"], _label(section, item, i),
                             f"entry {i + 1} of {section}")

    def _kilometre_posts(self):
        """[(at, km)] in mm: on the line, chainage and kilometrage strictly increasing."""
        d = self.d
        L = self.L
        kmp, prev = [], None
        for i, k in enumerate(d["kilometre_posts"]):
            entry = f"kilometre_posts[{i}]"
            at = self.mm(entry, "at_m", k["at_m"])
            km = self._scaled(entry, "km", k["km"], 1000000, "millimetres")
            if at is None or km is None:
                continue
            if at > L:
                self.err(entry, f"kilometre post km {k['km']} at {_m(at)} m is off the line "
                                f"[0, {_m(L)}] m")
            if prev is not None and (at <= prev[0] or km <= prev[1]):
                self.err(entry, f"kilometre posts must increase: km {k['km']} at {_m(at)} m "
                                f"does not follow km {prev[1] / 1e6:g} at {_m(prev[0])} m")
            kmp.append((at, km))
            prev = (at, km)
        return kmp

    def _tracks(self):
        """{id: track}: main tracks span the line, a loop lies strictly inside it."""
        d = self.d
        L = self.L
        tracks = {}
        for i, t in enumerate(d["tracks"]):
            if t["kind"] == "main" and any(k in t for k in ("from_m", "to_m", "points")):
                self.err(_label("tracks", t, i), "from_m, to_m and points belong to loops; a "
                                                 "main track spans the whole line")
            tracks.setdefault(t["id"], {"entry": _label("tracks", t, i), "kind": t["kind"],
                                        "range": (0, L) if t["kind"] == "main" else None,
                                        "raw": t})
        for tid, t in tracks.items():
            if t["kind"] == "loop":
                r = self._range(t["entry"], t["raw"])
                if r and (r[0] <= 0 or r[1] >= L):
                    self.err(t["entry"], f"loop {_sec(*r)} must lie strictly inside the line "
                                         f"[0, {_m(L)}) m")
                t["range"] = r
        if not any(t["kind"] == "main" for t in tracks.values()):
            self.err("tracks", "no main track")
        return tracks

    def _running_lines(self, tracks):
        """{id: running line}: on a main track, system boundary strictly inside the line."""
        d = self.d
        L = self.L
        rlines = {}
        for i, rl in enumerate(d["running_lines"]):
            entry = _label("running_lines", rl, i)
            t = tracks.get(rl["track"])
            track_ok = t is not None and t["kind"] == "main"
            if t is None:
                self.err(entry, f"unknown track {rl['track']!r}")
            elif t["kind"] != "main":
                self.err(entry, f"runs on {rl['track']!r}, a {t['kind']} track; running lines "
                                "run on main tracks")
            boundary = None
            if "system_boundary_m" in rl:
                boundary = self.mm(entry, "system_boundary_m", rl["system_boundary_m"])
                if boundary is not None and not 0 < boundary < L:
                    self.err(entry, f"system boundary at {_m(boundary)} m is off the line "
                                    f"(0, {_m(L)}) m")
            rlines.setdefault(rl["id"], {"entry": entry, "track": rl["track"],
                                         "inc": rl["direction"] == "increasing",
                                         "boundary": boundary, "ok": track_ok})
        return rlines

    def _virtual_blocks(self, tracks):
        """self.blocks: the sorted blocks of each track whose blocks tile it exactly, at most
        max_blocks of them. The blocks are counted from the entries' ranges and lengths
        before any is listed: a line of extreme length or tiny blocks is refused by its
        count, not built block by block."""
        d = self.d
        per_track = {}
        for i, vb in enumerate(d["virtual_blocks"]):
            entry = f"virtual_blocks[{i}]"
            if vb["track"] not in tracks:
                self.err(entry, f"unknown track {vb['track']!r}")
                continue
            r = self._range(entry, vb)
            n = None if r is None else r[1] - r[0]
            if r is not None and "length_m" in vb:
                n = self.mm(entry, "length_m", vb["length_m"])
                if n is None:
                    r = None
                elif (r[1] - r[0]) % n:
                    self.err(entry, f"range {_sec(*r)} is not a whole number of "
                                    f"{_m(n)} m blocks")
                    r = None
            per_track.setdefault(vb["track"], []).append((entry, r, n))
        limit = self.max_blocks if self.max_blocks is not None else BLOCKS_LIMIT
        self.blocks = {}  # track -> sorted blocks, only for tracks whose blocks are valid
        self.disjoint = {}  # track -> no two of its blocks overlap
        for tid, t in tracks.items():
            runs = per_track.get(tid, [])
            if not runs:
                self.err(t["entry"], "track has no virtual blocks")
                continue
            if t["range"] is None or any(r is None for _, r, _ in runs):
                continue
            self._cover(t["entry"], [(e, r) for e, r, _ in runs], *t["range"],
                        f"virtual blocks of track {tid}")
            count = sum((r[1] - r[0]) // n for _, r, n in runs)
            if count > limit:
                self.err(t["entry"], f"{count} virtual blocks exceed max_blocks {limit} "
                                     + ("(spec/parameters)" if self.max_blocks is not None
                                        else "(without spec/parameters: the largest count "
                                             "spec/schemas/parameters.schema.json admits)"))
                continue
            bl = sorted({(a, a + n) for _, r, n in runs for a in range(r[0], r[1], n)})
            self.blocks[tid] = bl
            self.disjoint[tid] = all(x[1] <= y[0] for x, y in zip(bl, bl[1:]))

    def _profile(self):
        """(gradients, speed limits, curves): gradients and limits cover the line, curves lie
        on it without overlapping."""
        d = self.d
        L = self.L
        grads = []
        for i, g in enumerate(d["gradients"]):
            entry = f"gradients[{i}]"
            r = self._range(entry, g)
            p = self._scaled(entry, "permille", g["permille"], 10, "0.1 permille")
            grads.append((entry, r, p))
        self._cover("gradients", [(e, r) for e, r, _ in grads], 0, L, "gradients")
        speeds = []
        for i, s in enumerate(d["speed_limits"]):
            entry = f"speed_limits[{i}]"
            speeds.append((entry, self._range(entry, s), s["kmh"]))
        self._cover("speed_limits", [(e, r) for e, r, _ in speeds], 0, L, "speed limits")
        curves = []
        for i, c in enumerate(d.get("curves") or []):
            entry = f"curves[{i}]"
            r = self._range(entry, c)
            if r is not None:
                curves.append((entry, r, c["radius_m"]))
        self._disjoint([(e, r) for e, r, _ in curves], 0, L, "curves")
        return grads, speeds, curves

    def _no_stop_sections(self):
        """[(entry, (a, b), id)] on the line, in order, not overlapping."""
        d = self.d
        L = self.L
        nostop = []
        for i, n in enumerate(d.get("no_stop_sections") or []):
            entry = _label("no_stop_sections", n, i)
            r = self._range(entry, n)
            if r is not None:
                nostop.append((entry, r, n["id"]))
        self._disjoint([(e, r) for e, r, _ in nostop], 0, L, "no-stop sections")
        return nostop

    def _balises(self, tracks):
        """[(id, track, at)] strictly inside their track."""
        d = self.d
        balises = []
        for i, b in enumerate(d["balises"]):
            entry = _label("balises", b, i)
            at = self.mm(entry, "at_m", b["at_m"])
            t = tracks.get(b["track"])
            if t is None:
                self.err(entry, f"unknown track {b['track']!r}")
                continue
            if at is None or t["range"] is None:
                continue
            lo, hi = t["range"]
            if not lo < at < hi:
                self.err(entry, f"balise at {_m(at)} m is off the line (strictly inside track "
                                f"{b['track']} {_sec(lo, hi)} required)")
                continue
            balises.append((b["id"], b["track"], at))
        return balises

    def _points(self, tracks):
        """(declared, points): each set of points on its track within exactly one virtual block
        of its own, reverse_to another existing track."""
        d = self.d
        # Points that fail a rule are reported once here; later rules skip what refers to
        # them (declared), so that one fault gives one message.
        declared = {}
        for p in d.get("points") or []:
            declared.setdefault(p["id"], p)
        points = {}
        block_owner = {}
        for i, p in enumerate(d.get("points") or []):
            entry = _label("points", p, i)
            t = tracks.get(p["track"])
            if t is None:
                self.err(entry, f"unknown track {p['track']!r}")
                continue
            if p["reverse_to"] not in tracks:
                self.err(entry, f"reverse_to: unknown track {p['reverse_to']!r}")
            elif p["reverse_to"] == p["track"]:
                self.err(entry, f"reverse_to: leads to its own track {p['track']!r}")
            r = self._range_on_track(entry, p, t, "points", "are")
            if r is None:
                continue
            if p["track"] not in self.blocks:
                continue  # the track's virtual blocks were rejected above
            hits = _overlapping(self.blocks[p["track"]], *r, self.disjoint[p["track"]])
            inside = [blk for blk in hits if blk[0] <= r[0] and r[1] <= blk[1]]
            if not hits:
                self.err(entry, f"point without a virtual block: no virtual block of track "
                                f"{p['track']} contains {_sec(*r)}")
                continue
            if not inside:
                self.err(entry, f"points {_sec(*r)} span {len(hits)} virtual blocks ("
                                + checks.listing(_sec(*blk) for blk in hits)
                                + "); points must lie within exactly one virtual block")
                continue
            blk = inside[0]
            other = block_owner.get((p["track"], blk))
            if other:
                self.err(entry, f"shares virtual block {_sec(*blk)} with {other}; each set of "
                                "points needs its own virtual block")
                continue
            block_owner[(p["track"], blk)] = entry
            points.setdefault(p["id"], {"entry": entry, "track": p["track"], "range": r,
                                        "block": blk, "reverse_to": p["reverse_to"]})
        return declared, points

    def _loops(self, tracks, declared, points):
        """A loop runs between its two points, which lie on one main track and lead to it."""
        for tid, t in tracks.items():
            if t["kind"] != "loop" or t["range"] is None:
                continue
            ends = t["raw"]["points"]
            for k, pid in enumerate(ends):
                raw = declared.get(pid)
                if raw is None:
                    self.err(t["entry"], f"points[{k}]: unknown points {pid!r}")
                    continue
                if tracks.get(raw["track"], {}).get("kind") != "main":
                    self.err(t["entry"], f"points {pid} lie on {raw['track']!r}, not on a main "
                                         "track")
                if raw["reverse_to"] != tid:
                    self.err(t["entry"], f"points {pid} lead (reverse) to "
                                         f"{raw['reverse_to']!r}, not to this loop")
                if pid not in points:
                    continue  # its extent was rejected above
                pt = points[pid]
                want = pt["range"][1] if k == 0 else pt["range"][0]
                have = t["range"][0] if k == 0 else t["range"][1]
                if want != have:
                    end = "from_m" if k == 0 else "to_m"
                    self.err(t["entry"], f"{end} {_m(have)} m does not meet points {pid} at "
                                         f"{_m(want)} m (a loop runs from the end of its first "
                                         "points to the start of its second)")
            if len(ends) == 2 and ends[0] in declared and ends[1] in declared \
                    and declared[ends[0]]["track"] != declared[ends[1]]["track"]:
                self.err(t["entry"], f"points {ends[0]} and {ends[1]} lie on different tracks")
            t["parent"] = declared[ends[0]]["track"] if ends[0] in declared else None

    def _routes(self, rlines, declared, points):
        """[route]: on an existing running line, in its direction, containing its points' block."""
        d = self.d
        L = self.L
        routes = []
        for i, ro in enumerate(d.get("routes") or []):
            entry = _label("routes", ro, i)
            rl = rlines.get(ro["running_line"])
            pt = points.get(ro["points"])
            if rl is None:
                self.err(entry, f"unknown running line {ro['running_line']!r}")
            if ro["points"] not in declared:
                self.err(entry, f"unknown points {ro['points']!r}")
            entry_mm = self.mm(entry, "entry_m", ro["entry_m"])
            exit_mm = self.mm(entry, "exit_m", ro["exit_m"])
            if rl is None or pt is None or entry_mm is None or exit_mm is None or not rl["ok"]:
                continue  # reported here or above
            if pt["track"] != rl["track"]:
                self.err(entry, f"points {ro['points']} lie on track {pt['track']!r}, not on "
                                f"running line {ro['running_line']}'s track {rl['track']!r}")
                continue
            if entry_mm > L or exit_mm > L:
                self.err(entry, f"route {_m(entry_mm)} -> {_m(exit_mm)} m is off the line "
                                f"[0, {_m(L)}] m")
                continue
            if (entry_mm < exit_mm) != rl["inc"] or entry_mm == exit_mm:
                self.err(entry, f"route {_m(entry_mm)} -> {_m(exit_mm)} m does not run in the "
                                f"direction of running line {ro['running_line']} "
                                f"({'increasing' if rl['inc'] else 'decreasing'} chainage)")
                continue
            lo, hi = min(entry_mm, exit_mm), max(entry_mm, exit_mm)
            blk = pt["block"]
            if not (lo <= blk[0] and blk[1] <= hi):
                self.err(entry, f"route {_sec(lo, hi)} does not contain the virtual block "
                                f"{_sec(*blk)} of its points {ro['points']}")
                continue
            routes.append({"id": ro["id"], "rl": ro["running_line"], "range": (lo, hi),
                           "points": ro["points"], "reverse": ro["position"] == "reverse",
                           "automatic": ro["automatic"]})
        return routes

    def _stations(self, tracks, rlines, nostop, train_mm):
        """[stop]: platforms on their track, long enough, not overlapping; each stop reachable,
        on its platform, outside no-stop sections, one per station and running line."""
        d = self.d
        stations = []
        plat_by_track = {}
        nostop_sections = _Sections(nostop)
        for i, st in enumerate(d["stations"]):
            sentry = _label("stations", st, i)
            served = {}
            for j, p in enumerate(st["platforms"]):
                entry = f"{sentry}.{_label('platforms', p, j)}"
                t = tracks.get(p["track"])
                if t is None:
                    self.err(entry, f"unknown track {p['track']!r}")
                    continue
                r = self._range_on_track(entry, p, t, "platform", "is")
                if r is None:
                    continue
                if train_mm is not None and r[1] - r[0] < train_mm:
                    self.err(entry, f"platform of {_m(r[1] - r[0])} m is shorter than the "
                                    f"design train ({_m(train_mm)} m)")
                plat_by_track.setdefault(p["track"], []).append((entry, r))
                for rid, stop_m in sorted(p["stops"].items()):
                    rl = rlines.get(rid)
                    if rl is None:
                        self.err(entry, f"stops.{rid}: unknown running line {rid!r}")
                        continue
                    stop = self.mm(entry, f"stops.{rid}", stop_m)
                    if stop is None or not rl["ok"]:
                        continue
                    if p["track"] != rl["track"] and t.get("parent") != rl["track"]:
                        self.err(entry, f"stops.{rid}: platform on track {p['track']!r} cannot "
                                        f"be reached by running line {rid} (track "
                                        f"{rl['track']!r})")
                        continue
                    inside = r[0] < stop <= r[1] if rl["inc"] else r[0] <= stop < r[1]
                    if not inside:
                        side = "(from, to]" if rl["inc"] else "[from, to)"
                        self.err(entry, f"stops.{rid}: stop point {_m(stop)} m is outside the "
                                        f"platform {_sec(*r)} (the front stops within {side} "
                                        f"for {'increasing' if rl['inc'] else 'decreasing'} "
                                        "chainage)")
                        continue
                    # in running coordinates the stop must not lie in [begin, end)
                    for ne, (na, nb), _nid in nostop_sections.at(stop, rl["inc"]):
                        self.err(entry, f"stops.{rid}: stop point {_m(stop)} m lies inside "
                                        f"no-stop section {ne} {_sec(na, nb)}")
                    if rid in served:
                        self.err(entry, f"stops.{rid}: station {st['name']} already has a stop "
                                        f"for running line {rid} ({served[rid]})")
                        continue
                    served[rid] = entry
                    stations.append({"name": st["name"], "platform": p["id"], "rl": rid,
                                     "range": r, "stop": stop, "fixed_block": p["fixed_block"],
                                     "setback": p["setback"], "entry": entry})
        for tid, plats in plat_by_track.items():
            plats = sorted(plats, key=lambda x: x[1])
            for (pe, (pa, pb)), (e, (a, b)) in zip(plats, plats[1:]):
                if a < pb:
                    self.err(e, f"platform {_sec(a, b)} overlaps {pe} {_sec(pa, pb)} on track "
                                f"{tid}")
        for rid in rlines:
            stops = sorted((s["stop"], s["entry"]) for s in stations if s["rl"] == rid)
            for (s1, e1), (s2, e2) in zip(stops, stops[1:]):
                if s1 == s2:
                    self.err(e2, f"stops.{rid}: same stop point {_m(s2)} m as {e1}")
        return stations

    def _radio(self):
        """(cells, handovers): cells cover the line, exactly one handover per cell boundary."""
        d = self.d
        L = self.L
        cells = []
        for i, c in enumerate(d["radio_cells"]):
            entry = _label("radio_cells", c, i)
            cells.append((entry, self._range(entry, c), c["id"]))
        self._cover("radio_cells", [(e, r) for e, r, _ in cells], 0, L, "radio cells")
        cells_known = all(r is not None for _, r, _ in cells)
        boundaries = {r[0]: e for e, r, _ in cells if r is not None and 0 < r[0] < L}
        handovers, at_boundary = [], {}
        listed = checks.listing(f"{_m(b)} m" for b in sorted(boundaries)) or "none"
        for i, h in enumerate(d["handovers"]):
            entry = _label("handovers", h, i)
            at = self.mm(entry, "at_m", h["at_m"])
            if at is None:
                continue
            if not 0 < at < L:
                self.err(entry, f"handover at {_m(at)} m is off the line (0, {_m(L)}) m")
                continue
            if not cells_known:
                continue  # the cells were rejected above
            if at not in boundaries:
                self.err(entry, f"handover at {_m(at)} m is not at a boundary between two radio "
                                f"cells (boundaries at: {listed})")
                continue
            if at in at_boundary:
                self.err(entry, f"second handover at the cell boundary {_m(at)} m "
                                f"(also {at_boundary[at]})")
                continue
            at_boundary[at] = entry
            handovers.append((h["id"], at))
        for b, cell_entry in sorted(boundaries.items()):
            if cells_known and b not in at_boundary:
                self.err(cell_entry, f"the cell boundary at {_m(b)} m has no handover point")
        return cells, handovers

    # ---- level crossings (REQ-LC-016)
    def _level_crossings(self, L, train_mm, nostop):
        """[(id, at, width, warning_ms)] of the valid crossings; every fault reported with
        the crossing's entry and the reason."""
        lcs = []
        for i, lc in enumerate(self.d.get("level_crossings") or []):
            entry = _label("level_crossings", lc, i)
            at = self.mm(entry, "at_m", lc["at_m"])
            width = self.mm(entry, "width_m", lc["width_m"])
            ok = at is not None and width is not None
            if width is not None and width <= 0:
                self.err(entry, f"road width {_m(width)} m is not positive")
                ok = False
            if "warning_time_s" in lc:
                warn = self._scaled(entry, "warning_time_s", lc["warning_time_s"], 1000,
                                    "milliseconds")
                if warn is None:
                    ok = False
                elif warn <= 0:
                    self.err(entry, f"design warning time {warn / 1000:g} s is not positive")
                    ok = False
            elif self.lc.default_warning_ms is not None:
                warn = self.lc.default_warning_ms
            else:
                self.err(entry, "no warning_time_s and no default_warning_time_ms in "
                                "spec/parameters (area LC)")
                warn, ok = None, False
            if warn is not None and warn > 0 and self.lc.min_warning_ms is not None \
                    and warn < self.lc.min_warning_ms:
                self.err(entry, f"design warning time {warn / 1000:g} s is below "
                                f"min_warning_time_ms {self.lc.min_warning_ms} ms "
                                "(spec/parameters/lc.yaml)")
                ok = False
            if not ok:
                continue
            near, far = crossing_extent(at, width)
            if not (0 < near and far < L):
                self.err(entry, f"level crossing {_sec(near, far)} (centre {_m(at)} m, road "
                                f"width {_m(width)} m) is off the line (0, {_m(L)}) m")
                continue
            lcs.append({"id": lc["id"], "entry": entry, "at": at, "width": width,
                        "warning_ms": warn, "range": (near, far)})
        # overlap: in order of the near edge, each must begin at or after the previous end
        prev = None
        for c in sorted(lcs, key=lambda c: c["range"]):
            if prev is not None and c["range"][0] < prev["range"][1]:
                self.err(c["entry"], f"level crossing {_sec(*c['range'])} overlaps "
                                     f"{prev['entry']} {_sec(*prev['range'])}")
            if prev is None or c["range"][1] > prev["range"][1]:
                prev = c
        # no-stop sections: no train of the design length may stand on a crossing (judged
        # only when every no-stop section was valid: one fault, one message)
        if train_mm is not None and len(nostop) == len(self.d.get("no_stop_sections") or []):
            nostop_sections = _Sections(nostop)
            for c in lcs:
                a, b = c["range"][0] - train_mm, c["range"][1] + train_mm
                if not nostop_sections.containing(a, b):
                    self.err(c["entry"], f"no no-stop section contains {_sec(max(a, 0), min(b, L))}"
                                         f" (the crossing {_sec(*c['range'])} widened by the "
                                         f"design train's {_m(train_mm)} m on both sides): a "
                                         "train could stop standing on the crossing")
        return lcs

    def _unique(self, seen, key, entry, where):
        if key in seen:
            self.err(entry, f"duplicate id {key!r} (first used by {seen[key]})")
        else:
            seen[key] = where

    # ---- conversion to running coordinates
    def _run_pos(self, x, inc):
        return x if inc else self.L - x

    def _run_sec(self, a, b, inc):
        return (a, b) if inc else (self.L - b, self.L - a)

    def _emit(self, kmp, rlines, grads, speeds, curves, balises, stations, points, routes,
              lcs, cells, handovers, nostop, train_mm):
        d, L = self.d, self.L
        out_lines = []
        for rid, rl in rlines.items():
            inc, tid = rl["inc"], rl["track"]

            def sec(a, b, inc=inc):
                return self._run_sec(a, b, inc)

            def pos(x, inc=inc):
                return self._run_pos(x, inc)

            bounds = sorted({pos(x) for blk in self.blocks[tid] for x in blk})
            gl = sorted((*sec(*r), p if inc else -p) for _, r, p in grads)
            sl = sorted((*sec(*r), k) for _, r, k in speeds)
            cl = sorted((*sec(*r), rad) for _, r, rad in curves)
            out_lines.append({
                "id": rid,
                "track": tid,
                "direction": "increasing" if inc else "decreasing",
                "length_mm": L,
                "blocks_mm": bounds,
                "gradients": [{"begin_mm": a, "end_mm": b, "permille_x10": p} for a, b, p in gl],
                "curves": [{"begin_mm": a, "end_mm": b, "radius_m": r} for a, b, r in cl],
                "speed_limits": [{"begin_mm": a, "end_mm": b, "kmh": k} for a, b, k in sl],
                "balises": [{"id": bid, "position_mm": p} for p, bid in
                            sorted((pos(at), bid) for bid, t, at in balises if t == tid)],
                "stations": [
                    {"name": s["name"], "platform": s["platform"],
                     "platform_begin_mm": sec(*s["range"])[0],
                     "platform_end_mm": sec(*s["range"])[1], "stop_mm": pos(s["stop"]),
                     "fixed_block": s["fixed_block"], "setback": s["setback"]}
                    for s in sorted((s for s in stations if s["rl"] == rid),
                                    key=lambda s: pos(s["stop"]))],
                "points": [{"id": pid, "begin_mm": a, "end_mm": b} for a, b, pid in
                           sorted((*sec(*p["block"]), pid) for pid, p in points.items()
                                  if p["track"] == tid)],
                "routes": [{"id": r["id"], "begin_mm": pos(r["range"][0] if inc else r["range"][1]),
                            "end_mm": pos(r["range"][1] if inc else r["range"][0]),
                            "points": r["points"], "reverse": r["reverse"],
                            "automatic": r["automatic"]}
                           for r in sorted((r for r in routes if r["rl"] == rid),
                                           key=lambda r: r["id"])],
                "level_crossings": [
                    {"id": c["id"], "position_mm": pos(c["at"]), "width_mm": c["width"],
                     "warning_time_ms": c["warning_ms"]}
                    for c in sorted(lcs, key=lambda c, pos=pos: (pos(c["at"]), c["id"]))],
                "radio_cells": [{"id": cid, "begin_mm": a, "end_mm": b} for a, b, cid in
                                sorted((*sec(*r), cid) for _, r, cid in cells)],
                "handovers": [{"id": hid, "position_mm": p} for p, hid in
                              sorted((pos(at), hid) for hid, at in handovers)],
                "no_stop_sections": [{"id": nid, "begin_mm": a, "end_mm": b} for a, b, nid in
                                     sorted((*sec(*r), nid) for _, r, nid in nostop)],
                "kilometre_posts": [{"position_mm": p, "kilometrage_mm": km} for p, km in
                                    sorted((pos(at), km) for at, km in kmp)],
                "system_boundary_mm": None if rl["boundary"] is None else pos(rl["boundary"]),
            })
        return {
            "schema": JSON_SCHEMA,
            "name": d["name"],
            "title": d["title"],
            "assumption": d["assumption"],
            "source": list(d["source"]),
            "design_train_length_mm": train_mm,
            "running_lines": out_lines,
        }


# --------------------------------------------------------------------------- API

def line_files(spec_dir):
    return spec_mod.spec_files(spec_dir, SUB)


def check_lines(spec_dir, report):
    """Check every spec/lines/*.yaml into `report` (validate.Report).

    Returns (outputs, refs): outputs maps name -> line JSON object for the files without
    errors; refs are (file, entry, field, text) of the assumption and source strings, for
    the cross-reference check of the caller (unknown ASM-NNN)."""
    spec_dir = Path(spec_dir)
    outputs, refs = {}, []
    lines_dir = spec_dir / SUB
    if not lines_dir.is_dir():
        return outputs, refs
    for bad in sorted(lines_dir.glob("*.yml")):
        report.error(bad, "-", "use the .yaml extension (files named *.yml are not read)")
    max_blocks = _max_blocks(spec_dir)
    lc_limits = _CrossingLimits.from_spec(spec_dir)

    def check(f, data):
        refs.extend(checks.provenance_refs(f, data["name"], data))
        obj = _Line(f, data, report, max_blocks, lc_limits).check()
        if obj is not None:
            outputs[data["name"]] = obj

    checks.check_data_files(spec_dir, line_files(spec_dir), SCHEMA_FILE, report, check)
    return outputs, refs


def build(spec_dir):
    """(outputs, report) for spec_dir: all line files checked, references resolved."""
    return checks.checked_directory(spec_dir, SUB, "line", check_lines,
                                  lambda _outputs: line_files(spec_dir))


def generate(spec_dir, out_dir):
    """Validate spec/lines and write OUT/<name>.json; raises SpecError (first error, with
    the count of the others) and writes nothing if any line file is invalid."""
    outputs, report = build(spec_dir)
    checks.raise_first(report)
    write_all({Path(out_dir) / f"{name}.json": spec_mod.render_json(obj)
               for name, obj in sorted(outputs.items())})
    return sorted(outputs)


def _converted(name, obj, path):
    rls = obj["running_lines"]
    return (f"{name}: {len(rls)} running line(s) ({', '.join(r['id'] for r in rls)}), "
            f"{_m(rls[0]['length_mm'])} m, {sum(len(r['blocks_mm']) - 1 for r in rls)} virtual "
            f"blocks -> {path}")


def run(args):
    return checks.convert(SUB, args, build, _converted)


def register(sub):
    add_command(sub, "lines", run, "validate spec/lines and write the line JSON for the simulation",
                """Check every spec/lines/*.yaml against spec/schemas/line.schema.json and the
                topology rules of spec/lines/README.md, then write OUT/<name>.json (schema
                railproof/line-json/1). Prints every finding as 'file: entry: reason'; on any
                error nothing is written and the exit status is 1.""",
                spec=SPEC_DIR, out="output directory (build/gen/lines)")
