// Line JSON loader and validator (contract: schema "railproof/line-json/1").
#include "railproof/offline/line.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <utility>

#include "railproof/core/units.hpp"
#include "railproof/offline/dynamics.hpp"
#include "railproof/generated/lc_params.hpp"
#include "railproof/offline/json_reader.hpp"

namespace railproof::offline {

namespace {

constexpr std::int64_t kMaxGradientPermilleX10 = 1000;  // 100 per mille: beyond any railway
constexpr std::int64_t kMaxSpeedKmh = 400;

std::string Mm(std::int64_t v) { return std::to_string(v); }

Section ReadSection(const JsonNode& n, std::int64_t length_mm) {
  Section s{n.Key("begin_mm").Int(), n.Key("end_mm").Int()};
  if (s.begin_mm < 0 || s.end_mm > length_mm) {
    n.Fail("section [" + Mm(s.begin_mm) + ", " + Mm(s.end_mm) + ") mm lies outside the line [0, " +
           Mm(length_mm) + ")");
  }
  if (s.begin_mm >= s.end_mm) {
    n.Fail("empty or reversed section: begin_mm " + Mm(s.begin_mm) + " >= end_mm " + Mm(s.end_mm));
  }
  return s;
}

std::int64_t ReadPosition(const JsonNode& n, std::int64_t length_mm) {
  const std::int64_t v = n.Int();
  if (v < 0 || v > length_mm) {
    n.Fail("position " + Mm(v) + " mm lies off the line [0, " + Mm(length_mm) + "]");
  }
  return v;
}

std::string ReadId(const JsonNode& n, std::set<std::string>& seen, std::string_view key = "id") {
  const JsonNode idn = n.Key(key);
  std::string id = idn.String();
  if (id.empty()) {
    idn.Fail("empty identifier");
  }
  if (!seen.insert(id).second) {
    idn.Fail("duplicate identifier '" + id + "'");
  }
  return id;
}

// Calls `read(node, id)` for every entry of the array `key` of `parent`, in order: `id` is the
// entry's identifier (member `id_key`: not empty, unique in the array) and `node` the entry
// labelled with it.
template <typename Read>
void ReadIdentified(const JsonNode& parent, std::string_view key, std::string_view id_key, const Read& read) {
  std::set<std::string> ids;
  for (const auto& entry : parent.Key(key).Array()) {
    std::string id = ReadId(entry, ids, id_key);
    const JsonNode labelled = entry.Labelled(id);  // before the id is moved (argument order is unspecified)
    read(labelled, std::move(id));
  }
}

// Sections that must cover [0, length) in order, without gap or overlap.
void CheckCover(const std::vector<JsonNode>& nodes, const std::vector<Section>& sections,
                std::int64_t length_mm, const JsonNode& parent, std::string_view what) {
  if (sections.empty()) {
    parent.Fail(std::string(what) + " must cover the line [0, " + Mm(length_mm) + "): none given");
  }
  std::int64_t expect = 0;
  for (std::size_t i = 0; i < sections.size(); ++i) {
    if (sections[i].begin_mm != expect) {
      nodes[i].Fail("begins at " + Mm(sections[i].begin_mm) + " mm, expected " + Mm(expect) +
                    " (sections must be sorted and cover the line without gap or overlap)");
    }
    expect = sections[i].end_mm;
  }
  if (expect != length_mm) {
    nodes.back().Fail("ends at " + Mm(expect) + " mm, the line ends at " + Mm(length_mm) + " (" +
                      std::string(what) + " must cover the whole line)");
  }
}

// Sections sorted by begin and not overlapping.
void CheckDisjoint(const std::vector<JsonNode>& nodes, const std::vector<Section>& sections) {
  for (std::size_t i = 1; i < sections.size(); ++i) {
    if (sections[i].begin_mm < sections[i - 1].end_mm) {
      nodes[i].Fail("begins at " + Mm(sections[i].begin_mm) + " mm, before the previous entry ends (" +
                    Mm(sections[i - 1].end_mm) + "): entries must be sorted and not overlap");
    }
  }
}

// Level crossings (REQ-LC-016): each names the crossing and the reason.
// @implements REQ-LC-016
void ReadLevelCrossings(const JsonNode& rn, std::int64_t length_mm, RunningLine& rl) {
  namespace lcp = railproof::params::lc;
  ReadIdentified(rn, "level_crossings", "id", [&](const JsonNode& n, std::string id) {
    LevelCrossing lc;
    lc.id = std::move(id);
    n.AllowOnly({"id", "position_mm", "width_mm", "warning_time_ms"});
    lc.position_mm = ReadPosition(n.Key("position_mm"), length_mm);
    lc.width_mm = n.Key("width_mm").Int();
    if (lc.width_mm <= 0) {
      n.Key("width_mm").Fail("level crossing " + lc.id + ": road width " + Mm(lc.width_mm) + " mm is not positive");
    }
    if (lc.width_mm >= length_mm) {
      n.Key("width_mm").Fail("level crossing " + lc.id + ": road width " + Mm(lc.width_mm) +
                             " mm is not less than the line length " + Mm(length_mm));
    }
    lc.warning_time_ms = n.Key("warning_time_ms").Int();
    if (lc.warning_time_ms <= 0) {
      n.Key("warning_time_ms")
          .Fail("level crossing " + lc.id + ": design warning time " + std::to_string(lc.warning_time_ms) +
                " ms is not positive");
    }
    if (lc.warning_time_ms < lcp::min_warning_time_ms) {
      n.Key("warning_time_ms")
          .Fail("level crossing " + lc.id + ": design warning time " + std::to_string(lc.warning_time_ms) +
                " ms is below min_warning_time_ms " + std::to_string(lcp::min_warning_time_ms) + " ms");
    }
    if (lc.warning_time_ms > lcp::max_warning_ms) {
      n.Key("warning_time_ms")
          .Fail("level crossing " + lc.id + ": design warning time " + std::to_string(lc.warning_time_ms) +
                " ms is above max_warning_ms " + std::to_string(lcp::max_warning_ms) + " ms");
    }
    if (lc.NearMm() <= 0 || lc.FarMm() >= length_mm) {
      n.Fail("level crossing " + lc.id + " [" + Mm(lc.NearMm()) + ", " + Mm(lc.FarMm()) + ") mm (centre " +
             Mm(lc.position_mm) + ", road width " + Mm(lc.width_mm) + ") lies off the line (0, " + Mm(length_mm) + ")");
    }
    if (!rl.level_crossings.empty()) {
      const LevelCrossing& prev = rl.level_crossings.back();
      if (lc.position_mm < prev.position_mm) {
        n.Fail("level crossing " + lc.id + " at " + Mm(lc.position_mm) + " mm listed after " + prev.id + " at " +
               Mm(prev.position_mm) + " mm (must be sorted)");
      }
      // sorted by centre: a crossing clear of its predecessor also ends after it, so the
      // predecessor is the only one it can overlap
      if (lc.NearMm() < prev.FarMm()) {
        n.Fail("level crossing " + lc.id + " [" + Mm(lc.NearMm()) + ", " + Mm(lc.FarMm()) + ") mm overlaps " + prev.id +
               " [" + Mm(prev.NearMm()) + ", " + Mm(prev.FarMm()) + ") mm");
      }
    }
    rl.level_crossings.push_back(lc);
  });
}

RunningLine ReadRunningLine(const JsonNode& rn0, std::set<std::string>& running_ids) {
  RunningLine rl;
  rl.id = ReadId(rn0, running_ids);
  const JsonNode rn = rn0.Labelled(rl.id);

  // at most the runtime's line coordinate range, so every position and section end (all
  // within [0, length]) and their sums with a train length stay far from int64 overflow
  rl.length_mm = rn.Key("length_mm").IntIn(1, core::kMaxPositionMm, "mm");
  const std::int64_t L = rl.length_mm;

  // Virtual blocks: boundaries 0 = b0 < b1 < ... < bn = length.
  const JsonNode bn = rn.Key("blocks_mm");
  const auto blocks = bn.Array();
  if (blocks.size() < 2) {
    bn.Fail("needs at least two boundaries (0 and the line length)");
  }
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const std::int64_t b = blocks[i].Int();
    if (i == 0 && b != 0) {
      blocks[i].Fail("the first block boundary must be 0, got " + Mm(b));
    }
    if (i > 0 && b <= rl.blocks_mm.back()) {
      blocks[i].Fail("block boundary " + Mm(b) + " not greater than the previous one " +
                     Mm(rl.blocks_mm.back()) + " (boundaries must be strictly increasing)");
    }
    rl.blocks_mm.push_back(b);
  }
  if (rl.blocks_mm.back() != L) {
    blocks.back().Fail("the last block boundary " + Mm(rl.blocks_mm.back()) + " must equal length_mm " + Mm(L));
  }

  {
    const JsonNode gn = rn.Key("gradients");
    const auto nodes = gn.Array();
    std::vector<Section> secs;
    for (const auto& n : nodes) {
      Gradient g{ReadSection(n, L), n.Key("permille_x10").Int()};
      if (g.permille_x10 < -kMaxGradientPermilleX10 || g.permille_x10 > kMaxGradientPermilleX10) {
        n.Key("permille_x10").Fail("gradient " + std::to_string(g.permille_x10) + " (x0.1 per mille) out of range");
      }
      secs.push_back(g.section);
      rl.gradients.push_back(g);
    }
    CheckCover(nodes, secs, L, gn, "gradients");
  }
  {
    const auto nodes = rn.Key("curves").Array();
    std::vector<Section> secs;
    for (const auto& n : nodes) {
      Curve c{ReadSection(n, L), n.Key("radius_m").Int()};
      if (c.radius_m <= 0) {
        n.Key("radius_m").Fail("radius must be positive");
      }
      secs.push_back(c.section);
      rl.curves.push_back(c);
    }
    CheckDisjoint(nodes, secs);
  }
  {
    const JsonNode sn = rn.Key("speed_limits");
    const auto nodes = sn.Array();
    std::vector<Section> secs;
    for (const auto& n : nodes) {
      SpeedLimit s{ReadSection(n, L), n.Key("kmh").Int()};
      if (s.kmh <= 0 || s.kmh > kMaxSpeedKmh) {
        n.Key("kmh").Fail("speed limit " + std::to_string(s.kmh) + " km/h out of range 1.." +
                          std::to_string(kMaxSpeedKmh));
      }
      secs.push_back(s.section);
      rl.speed_limits.push_back(s);
    }
    CheckCover(nodes, secs, L, sn, "speed_limits");
  }
  ReadIdentified(rn, "balises", "id", [&](const JsonNode& n, std::string id) {
    Balise b{std::move(id), ReadPosition(n.Key("position_mm"), L)};
    if (!rl.balises.empty() && b.position_mm < rl.balises.back().position_mm) {
      n.Fail("balise at " + Mm(b.position_mm) + " mm listed after one at " + Mm(rl.balises.back().position_mm) +
             " mm (must be sorted)");
    }
    rl.balises.push_back(b);
  });
  ReadIdentified(rn, "stations", "name", [&](const JsonNode& n, std::string name) {
    Station s;
    s.name = std::move(name);
    s.platform = Section{n.Key("platform_begin_mm").Int(), n.Key("platform_end_mm").Int()};
    if (s.platform.begin_mm < 0 || s.platform.end_mm > L || s.platform.begin_mm >= s.platform.end_mm) {
      n.Fail("platform [" + Mm(s.platform.begin_mm) + ", " + Mm(s.platform.end_mm) +
             ") mm is empty or lies outside the line");
    }
    s.stop_mm = n.Key("stop_mm").Int();
    if (s.stop_mm <= s.platform.begin_mm || s.stop_mm > s.platform.end_mm) {
      n.Key("stop_mm").Fail("stop " + Mm(s.stop_mm) + " mm lies outside the platform (" +
                            Mm(s.platform.begin_mm) + ", " + Mm(s.platform.end_mm) + "]");
    }
    s.fixed_block = n.Key("fixed_block").Bool();
    s.setback = n.Key("setback").Bool();
    if (!rl.stations.empty() && s.stop_mm <= rl.stations.back().stop_mm) {
      n.Fail("station stop " + Mm(s.stop_mm) + " mm not after the previous station's " +
             Mm(rl.stations.back().stop_mm) + " mm (must be sorted)");
    }
    rl.stations.push_back(s);
  });
  ReadIdentified(rn, "points", "id", [&](const JsonNode& n, std::string id) {
    Points p{std::move(id), ReadSection(n, L)};
    const auto it = std::find(rl.blocks_mm.begin(), rl.blocks_mm.end(), p.section.begin_mm);
    if (it == rl.blocks_mm.end() || std::next(it) == rl.blocks_mm.end() || *std::next(it) != p.section.end_mm) {
      n.Fail("points section [" + Mm(p.section.begin_mm) + ", " + Mm(p.section.end_mm) +
             ") mm is not exactly one virtual block");
    }
    rl.points.push_back(p);
  });
  {
    std::set<std::int64_t> ids;
    const auto nodes = rn.Key("routes").Array();
    for (const auto& n0 : nodes) {
      Route r;
      const JsonNode idn = n0.Key("id");
      r.id = idn.Int();
      if (r.id <= 0) {
        idn.Fail("route id must be positive");
      }
      if (!ids.insert(r.id).second) {
        idn.Fail("duplicate route id " + std::to_string(r.id));
      }
      const JsonNode n = n0.Labelled("route " + std::to_string(r.id));
      r.section = ReadSection(n, L);
      r.points = n.Key("points").String();
      r.reverse = n.Key("reverse").Bool();
      r.automatic = n.Key("automatic").Bool();
      const Points* p = rl.FindPoints(r.points);
      if (p == nullptr) {
        n.Key("points").Fail("unknown points '" + r.points + "'");
      }
      if (p->section.begin_mm < r.section.begin_mm || p->section.end_mm > r.section.end_mm) {
        n.Fail("route [" + Mm(r.section.begin_mm) + ", " + Mm(r.section.end_mm) + ") mm does not contain its points " +
               p->id);
      }
      rl.routes.push_back(r);
    }
  }
  ReadLevelCrossings(rn, L, rl);
  {
    std::set<std::string> ids;
    const JsonNode cn = rn.Key("radio_cells");
    const auto nodes = cn.Array();
    std::vector<Section> secs;
    for (const auto& n0 : nodes) {
      RadioCell c;
      c.id = ReadId(n0, ids);
      c.section = ReadSection(n0.Labelled(c.id), L);
      secs.push_back(c.section);
      rl.radio_cells.push_back(c);
    }
    CheckCover(nodes, secs, L, cn, "radio_cells");
  }
  ReadIdentified(rn, "handovers", "id", [&](const JsonNode& n, std::string id) {
    const JsonNode pn = n.Key("position_mm");
    Handover h{std::move(id), ReadPosition(pn, L)};
    const bool at_boundary = std::any_of(rl.radio_cells.begin(), rl.radio_cells.end(), [&](const RadioCell& c) {
      return c.section.begin_mm == h.position_mm && c.section.begin_mm > 0;
    });
    if (!at_boundary) {
      pn.Fail("handover at " + Mm(h.position_mm) + " mm is not at a boundary between two radio cells");
    }
    rl.handovers.push_back(h);
  });
  {
    const auto nodes = rn.Key("no_stop_sections").Array();
    for (const auto& n : nodes) {
      rl.no_stop_sections.push_back(ReadSection(n, L));
    }
    CheckDisjoint(nodes, rl.no_stop_sections);
  }
  {
    const JsonNode bn2 = rn.Key("system_boundary_mm");
    if (!bn2.IsNull()) {
      const std::int64_t b = bn2.Int();
      if (b <= 0 || b > L) {
        bn2.Fail("system boundary " + Mm(b) + " mm lies off the line (0, " + Mm(L) + "]");
      }
      rl.system_boundary_mm = b;
    }
  }
  return rl;
}

}  // namespace

std::int64_t RunningLine::GradientAt(std::int64_t pos_mm) const {
  for (const auto& g : gradients) {
    if (pos_mm < g.section.end_mm) {
      return g.permille_x10;
    }
  }
  return gradients.empty() ? 0 : gradients.back().permille_x10;
}

namespace {

// ∫ f over [lo, hi] (mm x the value's unit) for a value that is `value(i)` on sections[i].
template <typename Pieces, typename Value>
double IntegralOver(const Pieces& pieces, double lo, double hi, Value value) {
  double sum = 0.0;
  for (const auto& p : pieces) {
    const double a = std::max(lo, static_cast<double>(p.section.begin_mm));
    const double b = std::min(hi, static_cast<double>(p.section.end_mm));
    if (b > a) {
      sum += (b - a) * value(p);
    }
  }
  return sum;
}

}  // namespace

double RunningLine::MeanGradientPermille(double rear_mm, double front_mm) const {
  const auto permille = [](const Gradient& g) { return static_cast<double>(g.permille_x10) / 10.0; };
  if (gradients.empty()) {
    return 0.0;
  }
  if (!(front_mm > rear_mm)) {
    return static_cast<double>(GradientAt(static_cast<std::int64_t>(std::floor(rear_mm)))) / 10.0;
  }
  const double begin = static_cast<double>(gradients.front().section.begin_mm);
  const double end = static_cast<double>(gradients.back().section.end_mm);
  double sum = IntegralOver(gradients, rear_mm, front_mm, permille);
  sum += std::max(0.0, std::min(front_mm, begin) - rear_mm) * permille(gradients.front());
  sum += std::max(0.0, front_mm - std::max(rear_mm, end)) * permille(gradients.back());
  return sum / (front_mm - rear_mm);
}

double RunningLine::MeanCurveResistancePermille(double rear_mm, double front_mm) const {
  if (!(front_mm > rear_mm)) {
    for (const Curve& c : curves) {
      if (static_cast<double>(c.section.begin_mm) <= rear_mm && rear_mm < static_cast<double>(c.section.end_mm)) {
        return CurveResistancePermille(static_cast<double>(c.radius_m));
      }
    }
    return 0.0;
  }
  return IntegralOver(curves, rear_mm, front_mm,
                      [](const Curve& c) { return CurveResistancePermille(static_cast<double>(c.radius_m)); }) /
         (front_mm - rear_mm);
}

std::int64_t RunningLine::SpeedLimitAt(std::int64_t pos_mm) const {
  for (const auto& s : speed_limits) {
    if (pos_mm < s.section.end_mm) {
      return s.kmh;
    }
  }
  return speed_limits.empty() ? 0 : speed_limits.back().kmh;
}

const Station* RunningLine::FindStation(std::string_view name) const {
  for (const auto& s : stations) {
    if (s.name == name) {
      return &s;
    }
  }
  return nullptr;
}

const Points* RunningLine::FindPoints(std::string_view points_id) const {
  for (const auto& p : points) {
    if (p.id == points_id) {
      return &p;
    }
  }
  return nullptr;
}

const RunningLine& Line::Running(std::string_view running_id) const {
  std::string have;
  for (const auto& rl : running_lines) {
    if (rl.id == running_id) {
      return rl;
    }
    have += (have.empty() ? "" : ", ") + rl.id;
  }
  throw InputError(file + ": unknown running line '" + std::string(running_id) + "' (the line has: " + have + ")");
}

Line ParseLine(std::string_view text, const std::string& file) {
  const JsonDocument root(text, file, kLineSchema);
  Line line;
  line.file = file;
  line.name = root.Key("name").String();
  if (line.name.empty()) {
    root.Key("name").Fail("empty name");
  }
  line.title = root.Key("title").String();
  line.assumption = root.Key("assumption").String();
  for (const auto& s : root.Key("source").Array()) {
    line.source.push_back(s.String());
  }
  std::set<std::string> ids;
  for (const auto& n : root.Key("running_lines").NonEmptyArray("no running line")) {
    line.running_lines.push_back(ReadRunningLine(n, ids));
  }
  return line;
}

Line LoadLine(const std::filesystem::path& path) { return ParseLine(ReadInputFile(path, "line file"), path.string()); }

std::filesystem::path LinePath(const std::filesystem::path& lines_dir, std::string_view name) {
  return lines_dir / (std::string(name) + ".json");
}

}  // namespace railproof::offline
