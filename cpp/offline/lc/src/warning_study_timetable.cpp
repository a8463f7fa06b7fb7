// Timetable of the warning-time study: the YAML-subset reader, parsing and the checks
// against the line and the train types (warning_study.hpp, spec/timetables/README.md).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <utility>

#include "railproof/lc/analysis/warning_study.hpp"
#include "railproof/offline/json_reader.hpp"

namespace railproof::lc::analysis {

using offline::InputError;
using offline::JsonNode;

// ============================================================================ YAML subset
// Written here because the C++ build has no YAML library (spec/timetables/README.md lists
// the subset). Recursive descent over flow collections (offline code; the nesting depth is
// bounded by kMaxDepth).

namespace {

constexpr int kMaxDepth = 32;

struct Line {
  int number = 0;  // 1-based
  int indent = 0;
  std::string text;  // without indentation and comment, right-trimmed
};

class YamlReader {
 public:
  YamlReader(std::string_view text, const std::string& file) : file_(file) { Split(text); }

  nlohmann::json Document() {
    if (lines_.empty()) {
      return nlohmann::json::object();
    }
    if (lines_[0].indent != 0) {
      Fail(lines_[0].number, "the document must start at column 1");
    }
    nlohmann::json doc = Block(0, 0);
    if (pos_ < lines_.size()) {
      Fail(lines_[pos_].number, "unexpected indentation");
    }
    return doc;
  }

 private:
  [[noreturn]] void Fail(int line, const std::string& reason) const {
    throw InputError(file_ + ":" + std::to_string(line) + ": " + reason);
  }

  // Removes a comment: '#' at the start or after a blank, outside quotes.
  static std::string StripComment(const std::string& s) {
    char quote = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const char c = s[i];
      if (quote != 0) {
        if (c == '\\' && quote == '"') {
          ++i;
        } else if (c == quote) {
          quote = 0;
        }
        continue;
      }
      if ((c == '"' || c == '\'') && (i == 0 || std::string_view(" \t[{,:").find(s[i - 1]) != std::string_view::npos)) {
        quote = c;
      } else if (c == '#' && (i == 0 || s[i - 1] == ' ' || s[i - 1] == '\t')) {
        return s.substr(0, i);
      }
    }
    return s;
  }

  void Split(std::string_view text) {
    std::size_t start = 0;
    int number = 0;
    while (start <= text.size()) {
      std::size_t end = text.find('\n', start);
      if (end == std::string_view::npos) {
        end = text.size();
      }
      ++number;
      std::string raw(text.substr(start, end - start));
      if (!raw.empty() && raw.back() == '\r') {
        raw.pop_back();
      }
      std::size_t ind = 0;
      while (ind < raw.size() && raw[ind] == ' ') {
        ++ind;
      }
      if (ind < raw.size() && raw[ind] == '\t') {
        Fail(number, "tab in indentation (use spaces)");
      }
      std::string body = StripComment(raw.substr(ind));
      while (!body.empty() && (body.back() == ' ' || body.back() == '\t')) {
        body.pop_back();
      }
      if (!body.empty()) {
        if (body == "---" || body == "...") {
          Fail(number, "document markers are not supported (one document per file)");
        }
        lines_.push_back(Line{number, static_cast<int>(ind), body});
      }
      if (end == text.size()) {
        break;
      }
      start = end + 1;
    }
  }

  // Block at exactly `indent` (a mapping or a sequence).
  nlohmann::json Block(int indent, int depth) {
    if (depth > kMaxDepth) {
      Fail(lines_[pos_].number, "nesting too deep");
    }
    const Line& first = lines_[pos_];
    if (first.text == "-" || first.text.rfind("- ", 0) == 0) {
      return Sequence(indent, depth);
    }
    return Mapping(indent, depth);
  }

  nlohmann::json Sequence(int indent, int depth) {
    nlohmann::json seq = nlohmann::json::array();
    while (pos_ < lines_.size() && lines_[pos_].indent == indent) {
      const Line& ln = lines_[pos_];
      if (!(ln.text == "-" || ln.text.rfind("- ", 0) == 0)) {
        Fail(ln.number, "expected a sequence item '- ...' at this indentation");
      }
      std::string rest = ln.text.size() > 1 ? ln.text.substr(2) : "";
      while (!rest.empty() && rest.front() == ' ') {
        rest.erase(rest.begin());
      }
      const int number = ln.number;
      ++pos_;
      if (rest.empty()) {
        if (pos_ < lines_.size() && lines_[pos_].indent > indent) {
          seq.push_back(Block(lines_[pos_].indent, depth + 1));
        } else {
          seq.push_back(nullptr);
        }
        continue;
      }
      if (rest[0] != '{' && rest[0] != '[' && rest[0] != '"' && rest[0] != '\'' && FindKeyColon(rest) != std::string::npos) {
        Fail(number, "a block mapping inside a sequence item is not supported: write the item as a flow mapping {key: value, ...}");
      }
      seq.push_back(InlineValue(rest, number, depth));
    }
    if (pos_ < lines_.size() && lines_[pos_].indent > indent) {
      Fail(lines_[pos_].number, "unexpected indentation");
    }
    return seq;
  }

  // Position of the ':' that ends a plain key ("key: value" or "key:"), npos if none.
  static std::size_t FindKeyColon(const std::string& s) {
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s[i] == ':' && (i + 1 == s.size() || s[i + 1] == ' ')) {
        return i;
      }
      if (s[i] == '{' || s[i] == '[' || s[i] == ',') {
        return std::string::npos;
      }
    }
    return std::string::npos;
  }

  nlohmann::json Mapping(int indent, int depth) {
    nlohmann::json map = nlohmann::json::object();
    while (pos_ < lines_.size() && lines_[pos_].indent == indent) {
      const Line& ln = lines_[pos_];
      const int number = ln.number;
      std::string key;
      std::size_t after = 0;
      if (ln.text[0] == '"' || ln.text[0] == '\'') {
        std::size_t i = 0;
        key = Quoted(ln.text, i, number);
        if (i >= ln.text.size() || ln.text[i] != ':') {
          Fail(number, "expected ':' after the quoted key");
        }
        after = i + 1;
      } else {
        const std::size_t c = FindKeyColon(ln.text);
        if (c == std::string::npos) {
          Fail(number, "expected 'key: value' (a mapping entry)");
        }
        key = ln.text.substr(0, c);
        after = c + 1;
      }
      if (key.empty()) {
        Fail(number, "empty key");
      }
      if (map.contains(key)) {
        Fail(number, "duplicate key '" + key + "'");
      }
      std::string rest = ln.text.substr(after);
      while (!rest.empty() && rest.front() == ' ') {
        rest.erase(rest.begin());
      }
      ++pos_;
      if (rest.empty()) {
        if (pos_ < lines_.size() && lines_[pos_].indent > indent) {
          map[key] = Block(lines_[pos_].indent, depth + 1);
        } else if (pos_ < lines_.size() && lines_[pos_].indent == indent &&
                   (lines_[pos_].text == "-" || lines_[pos_].text.rfind("- ", 0) == 0)) {
          map[key] = Sequence(indent, depth + 1);  // "key:\n- item" at the same indentation
        } else {
          map[key] = nullptr;
        }
      } else {
        map[key] = InlineValue(rest, number, depth);
      }
    }
    if (pos_ < lines_.size() && lines_[pos_].indent > indent) {
      Fail(lines_[pos_].number, "unexpected indentation");
    }
    return map;
  }

  // A value on one line; a flow collection may continue on the following (more indented) lines.
  nlohmann::json InlineValue(std::string text, int number, int depth) {
    if (text[0] == '{' || text[0] == '[') {
      while (!Balanced(text)) {
        if (pos_ >= lines_.size()) {
          Fail(number, "unterminated flow collection");
        }
        text += " " + lines_[pos_].text;
        ++pos_;
      }
    }
    std::size_t i = 0;
    nlohmann::json v = Flow(text, i, number, depth, false);
    SkipBlanks(text, i);
    if (i != text.size()) {
      Fail(number, "unexpected text after the value: '" + text.substr(i) + "'");
    }
    return v;
  }

  static bool Balanced(const std::string& s) {
    int level = 0;
    char quote = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const char c = s[i];
      if (quote != 0) {
        if (c == '\\' && quote == '"') {
          ++i;
        } else if (c == quote) {
          quote = 0;
        }
        continue;
      }
      if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '{' || c == '[') {
        ++level;
      } else if (c == '}' || c == ']') {
        --level;
      }
    }
    return level <= 0;
  }

  static void SkipBlanks(const std::string& s, std::size_t& i) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) {
      ++i;
    }
  }

  std::string Quoted(const std::string& s, std::size_t& i, int number) const {
    const char q = s[i++];
    std::string out;
    while (true) {
      if (i >= s.size()) {
        Fail(number, "unterminated quoted string");
      }
      const char c = s[i++];
      if (q == '\'' && c == '\'') {
        if (i < s.size() && s[i] == '\'') {
          out += '\'';
          ++i;
          continue;
        }
        return out;
      }
      if (q == '"' && c == '"') {
        return out;
      }
      if (q == '"' && c == '\\') {
        if (i >= s.size()) {
          Fail(number, "unterminated escape");
        }
        const char e = s[i++];
        switch (e) {
          case 'n': out += '\n'; break;
          case 't': out += '\t'; break;
          case '"': out += '"'; break;
          case '\\': out += '\\'; break;
          case '/': out += '/'; break;
          default: Fail(number, std::string("unsupported escape '\\") + e + "'");
        }
        continue;
      }
      out += c;
    }
  }

  static nlohmann::json Scalar(const std::string& raw) {
    std::string s = raw;
    while (!s.empty() && s.back() == ' ') {
      s.pop_back();
    }
    if (s.empty() || s == "~" || s == "null") {
      return nullptr;
    }
    if (s == "true") {
      return true;
    }
    if (s == "false") {
      return false;
    }
    std::size_t i = (s[0] == '-' || s[0] == '+') ? 1 : 0;
    bool digits = i < s.size();
    for (std::size_t k = i; k < s.size(); ++k) {
      digits = digits && std::isdigit(static_cast<unsigned char>(s[k])) != 0;
    }
    if (digits && s.size() - i <= 18) {
      return static_cast<std::int64_t>(std::stoll(s));
    }
    // decimal: [+-]digits.digits with optional exponent
    std::size_t k = i, ds = 0;
    while (k < s.size() && std::isdigit(static_cast<unsigned char>(s[k])) != 0) {
      ++k, ++ds;
    }
    if (k < s.size() && s[k] == '.') {
      ++k;
      while (k < s.size() && std::isdigit(static_cast<unsigned char>(s[k])) != 0) {
        ++k, ++ds;
      }
      if (ds > 0 && k < s.size() && (s[k] == 'e' || s[k] == 'E')) {
        ++k;
        if (k < s.size() && (s[k] == '+' || s[k] == '-')) {
          ++k;
        }
        std::size_t es = 0;
        while (k < s.size() && std::isdigit(static_cast<unsigned char>(s[k])) != 0) {
          ++k, ++es;
        }
        if (es == 0) {
          return s;
        }
      }
      if (ds > 0 && k == s.size()) {
        return std::stod(s);
      }
    }
    return s;
  }

  // A flow value starting at s[i]: {..}, [..], quoted or plain scalar. In a flow collection a
  // plain scalar ends at ',', ']' or '}' (and a key at ': ').
  nlohmann::json Flow(const std::string& s, std::size_t& i, int number, int depth, bool in_flow) {
    if (depth > kMaxDepth) {
      Fail(number, "nesting too deep");
    }
    SkipBlanks(s, i);
    if (i >= s.size()) {
      return nullptr;
    }
    const char c = s[i];
    if (c == '{') {
      ++i;
      nlohmann::json map = nlohmann::json::object();
      SkipBlanks(s, i);
      if (i < s.size() && s[i] == '}') {
        ++i;
        return map;
      }
      while (true) {
        SkipBlanks(s, i);
        std::string key;
        if (i < s.size() && (s[i] == '"' || s[i] == '\'')) {
          key = Quoted(s, i, number);
        } else {
          const std::size_t b = i;
          while (i < s.size() && !(s[i] == ':' && (i + 1 == s.size() || s[i + 1] == ' ' || s[i + 1] == ',' || s[i + 1] == '}')) &&
                 s[i] != ',' && s[i] != '}') {
            ++i;
          }
          key = s.substr(b, i - b);
          while (!key.empty() && key.back() == ' ') {
            key.pop_back();
          }
        }
        SkipBlanks(s, i);
        if (i >= s.size() || s[i] != ':') {
          Fail(number, "expected ':' after the key '" + key + "' in a flow mapping");
        }
        ++i;
        if (key.empty()) {
          Fail(number, "empty key in a flow mapping");
        }
        if (map.contains(key)) {
          Fail(number, "duplicate key '" + key + "'");
        }
        map[key] = Flow(s, i, number, depth + 1, true);
        SkipBlanks(s, i);
        if (i < s.size() && s[i] == ',') {
          ++i;
          continue;
        }
        if (i < s.size() && s[i] == '}') {
          ++i;
          return map;
        }
        Fail(number, "expected ',' or '}' in a flow mapping");
      }
    }
    if (c == '[') {
      ++i;
      nlohmann::json seq = nlohmann::json::array();
      SkipBlanks(s, i);
      if (i < s.size() && s[i] == ']') {
        ++i;
        return seq;
      }
      while (true) {
        seq.push_back(Flow(s, i, number, depth + 1, true));
        SkipBlanks(s, i);
        if (i < s.size() && s[i] == ',') {
          ++i;
          continue;
        }
        if (i < s.size() && s[i] == ']') {
          ++i;
          return seq;
        }
        Fail(number, "expected ',' or ']' in a flow sequence");
      }
    }
    if (c == '"' || c == '\'') {
      return Quoted(s, i, number);
    }
    if (c == '}' || c == ']' || c == ',') {
      Fail(number, std::string("unexpected '") + c + "'");
    }
    const std::size_t b = i;
    if (in_flow) {
      while (i < s.size() && s[i] != ',' && s[i] != ']' && s[i] != '}') {
        ++i;
      }
    } else {
      i = s.size();
    }
    const std::string plain = s.substr(b, i - b);
    if (!in_flow && FindKeyColon(plain) != std::string::npos) {
      Fail(number, "a block mapping value cannot follow on the same line: '" + plain + "'");
    }
    return Scalar(plain);
  }

  std::string file_;
  std::vector<Line> lines_;
  std::size_t pos_ = 0;
};

}  // namespace

nlohmann::json ParseYamlSubset(std::string_view text, const std::string& file) {
  YamlReader r(text, file);
  return r.Document();
}

// ============================================================================ timetable

std::optional<std::int64_t> ParseClockTime(std::string_view text) {
  int h = 0, m = 0, s = 0;
  char tail = 0;
  const std::string t(text);
  int n = 0;
  if (t.size() == 8 && std::sscanf(t.c_str(), "%2d:%2d:%2d%c", &h, &m, &s, &tail) == 3) {
    n = 3;
  } else if (t.size() == 5 && std::sscanf(t.c_str(), "%2d:%2d%c", &h, &m, &tail) == 2) {
    n = 2;
  }
  if (n == 0) {
    return std::nullopt;
  }
  for (std::size_t i = 0; i < t.size(); ++i) {
    const bool colon = (i == 2 || i == 5);
    if (colon ? t[i] != ':' : std::isdigit(static_cast<unsigned char>(t[i])) == 0) {
      return std::nullopt;
    }
  }
  if (h < 0 || h > 47 || m < 0 || m > 59 || s < 0 || s > 59) {
    return std::nullopt;
  }
  return (static_cast<std::int64_t>(h) * 3600 + m * 60 + s) * 1000;
}

std::string FormatClockTime(std::int64_t ms) {
  const std::int64_t s = ms / 1000;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%02lld:%02lld:%02lld", static_cast<long long>(s / 3600),
                static_cast<long long>((s / 60) % 60), static_cast<long long>(s % 60));
  return buf;
}

namespace {

std::int64_t IntIn(const JsonNode& n, std::int64_t lo, std::int64_t hi, const char* unit) {
  const std::int64_t v = n.Int();
  if (v < lo || v > hi) {
    n.Fail(std::to_string(v) + " " + unit + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return v;
}

// Seconds (integer or decimal, whole ms) -> ms.
std::int64_t SecondsIn(const JsonNode& n, double lo_s, double hi_s) {
  const double v = n.Number();
  if (v < lo_s || v > hi_s) {
    n.Fail(n.Value().dump() + " s is outside [" + std::to_string(static_cast<long long>(lo_s)) + ", " +
           std::to_string(static_cast<long long>(hi_s)) + "] s");
  }
  const double ms = v * 1000.0;
  const double r = std::round(ms);
  if (std::fabs(ms - r) > 1e-6) {
    n.Fail(n.Value().dump() + " s is not a whole number of milliseconds");
  }
  return static_cast<std::int64_t>(r);
}

RangeMs RangeSeconds(const JsonNode& n, double lo_s, double hi_s) {
  const auto items = n.Array();
  if (items.size() != 2) {
    n.Fail("expected [min, max] in seconds, got " + std::to_string(items.size()) + " element(s)");
  }
  RangeMs r{SecondsIn(items[0], lo_s, hi_s), SecondsIn(items[1], lo_s, hi_s)};
  if (r.min > r.max) {
    n.Fail("min " + items[0].Value().dump() + " s is greater than max " + items[1].Value().dump() + " s");
  }
  return r;
}

RangeMs RangeMillis(const JsonNode& n, std::int64_t lo, std::int64_t hi) {
  const auto items = n.Array();
  if (items.size() != 2) {
    n.Fail("expected [min, max] in ms, got " + std::to_string(items.size()) + " element(s)");
  }
  RangeMs r{IntIn(items[0], lo, hi, "ms"), IntIn(items[1], lo, hi, "ms")};
  if (r.min > r.max) {
    n.Fail("min " + std::to_string(r.min) + " ms is greater than max " + std::to_string(r.max) + " ms");
  }
  return r;
}

std::string NonEmptyString(const JsonNode& n) {
  std::string s = n.String();
  if (s.empty()) {
    n.Fail("empty string");
  }
  return s;
}

}  // namespace

Timetable ParseTimetable(std::string_view text, const std::string& file) {
  const nlohmann::json doc = ParseYamlSubset(text, file);
  const JsonNode root(doc, "", file);
  root.AllowOnly({"schema", "name", "line", "title", "source", "assumption", "note", "seed", "running_time_allowance_percent",
                  "planned_time_step_s", "driver", "communication", "services"});
  const std::string schema = root.Key("schema").String();
  if (schema != kTimetableSchema) {
    root.Key("schema").Fail("unsupported schema '" + schema + "', expected '" + std::string(kTimetableSchema) + "'");
  }
  Timetable tt;
  tt.file = file;
  tt.name = NonEmptyString(root.Key("name"));
  tt.line = NonEmptyString(root.Key("line"));
  tt.title = NonEmptyString(root.Key("title"));
  for (const auto& s : root.Key("source").Array()) {
    (void)NonEmptyString(s);
  }
  if (const auto a = root.OptKey("assumption")) {
    (void)NonEmptyString(*a);
  }
  if (const auto a = root.OptKey("note")) {
    (void)a->String();
  }
  tt.seed = static_cast<std::uint64_t>(IntIn(root.Key("seed"), 0, std::int64_t{1} << 53, ""));
  tt.running_time_allowance_percent = IntIn(root.Key("running_time_allowance_percent"), 0, 100, "%");
  if (const auto st = root.OptKey("planned_time_step_s")) {
    tt.planned_time_step_ms = SecondsIn(*st, 1, 300);
  }
  {
    const JsonNode d = root.Key("driver");
    d.AllowOnly({"cruise_percent", "start_delay_s", "min_dwell_s"});
    const JsonNode cp = d.Key("cruise_percent");
    const auto items = cp.Array();
    if (items.size() != 2) {
      cp.Fail("expected [min, max] in %, got " + std::to_string(items.size()) + " element(s)");
    }
    tt.driver.cruise_min_percent = IntIn(items[0], 50, 100, "%");
    tt.driver.cruise_max_percent = IntIn(items[1], 50, 100, "%");
    if (tt.driver.cruise_min_percent > tt.driver.cruise_max_percent) {
      cp.Fail("min " + std::to_string(tt.driver.cruise_min_percent) + " % is greater than max " +
              std::to_string(tt.driver.cruise_max_percent) + " %");
    }
    tt.driver.start_delay_ms = RangeSeconds(d.Key("start_delay_s"), 0, 600);
    tt.driver.min_dwell_ms = SecondsIn(d.Key("min_dwell_s"), 0, 3600);
  }
  {
    const JsonNode c = root.Key("communication");
    c.AllowOnly({"uplink_ms", "downlink_ms", "ground_cycle_ms", "onboard_cycle_ms", "barrier_travel_s", "report_latency_ms",
                 "onboard_clock_error_ms", "gnss_clock_error_ms"});
    tt.comms.uplink_ms = RangeMillis(c.Key("uplink_ms"), 0, 60'000);
    tt.comms.downlink_ms = RangeMillis(c.Key("downlink_ms"), 0, 60'000);
    tt.comms.ground_cycle_ms = IntIn(c.Key("ground_cycle_ms"), 1, 10'000, "ms");
    tt.comms.onboard_cycle_ms = IntIn(c.Key("onboard_cycle_ms"), 1, 10'000, "ms");
    tt.comms.barrier_travel_ms = RangeSeconds(c.Key("barrier_travel_s"), 0, 60);
    tt.comms.report_latency_ms = RangeMillis(c.Key("report_latency_ms"), 0, 60'000);
    tt.comms.onboard_clock_error_ms = IntIn(c.Key("onboard_clock_error_ms"), 0, 10'000, "ms");
    tt.comms.gnss_clock_error_ms = IntIn(c.Key("gnss_clock_error_ms"), 0, 10'000, "ms");
  }
  const JsonNode sn = root.Key("services");
  const auto nodes = sn.Array();
  if (nodes.empty()) {
    sn.Fail("no services");
  }
  std::set<std::string> ids;
  for (const auto& n0 : nodes) {
    Service s;
    const JsonNode idn = n0.Key("id");
    s.id = idn.Value().is_number_integer() ? std::to_string(idn.Int()) : NonEmptyString(idn);
    if (!ids.insert(s.id).second) {
      idn.Fail("duplicate service id '" + s.id + "'");
    }
    const JsonNode n = n0.Labelled(s.id);
    n.AllowOnly({"id", "train", "running_line", "depart", "from", "to", "stops", "dwell_s", "note"});
    s.train = NonEmptyString(n.Key("train"));
    s.running_line = NonEmptyString(n.Key("running_line"));
    const JsonNode dep = n.Key("depart");
    const auto t = ParseClockTime(dep.String());
    if (!t) {
      dep.Fail("'" + dep.String() + "' is not a time \"HH:MM\" or \"HH:MM:SS\" (hours 0-47)");
    }
    s.depart_ms = *t;
    if (const auto f = n.OptKey("from")) {
      s.from = NonEmptyString(*f);
    }
    if (const auto f = n.OptKey("to")) {
      s.to = NonEmptyString(*f);
    }
    // dwell_s: one number for every stop, or a mapping station -> seconds with "default"
    std::int64_t default_dwell = -1;
    std::map<std::string, std::int64_t> dwell_of;
    std::optional<JsonNode> dwn = n.OptKey("dwell_s");
    if (dwn) {
      if (dwn->Value().is_object()) {
        for (const auto& [k, v] : dwn->Value().items()) {
          const JsonNode e = dwn->Key(k);
          dwell_of[k] = SecondsIn(e, 0, 3600);
          (void)v;
        }
        if (dwell_of.count("default") != 0U) {
          default_dwell = dwell_of["default"];
          dwell_of.erase("default");
        }
      } else {
        default_dwell = SecondsIn(*dwn, 0, 3600);
      }
    }
    const JsonNode stn = n.Key("stops");
    std::set<std::string> named;
    for (const auto& st : stn.Array()) {
      ServiceStop stop;
      stop.station = NonEmptyString(st);
      if (!named.insert(stop.station).second) {
        st.Fail("station '" + stop.station + "' named twice");
      }
      const auto it = dwell_of.find(stop.station);
      if (it != dwell_of.end()) {
        stop.dwell_ms = it->second;
      } else if (default_dwell >= 0) {
        stop.dwell_ms = default_dwell;
      } else {
        st.Fail("no dwell for the stop at '" + stop.station + "' (give dwell_s as a number or with 'default')");
      }
      s.stops.push_back(stop);
    }
    for (const auto& [k, v] : dwell_of) {
      if (named.count(k) == 0U) {
        dwn->Key(k).Fail("dwell for '" + k + "', which is not one of the stops");
      }
      (void)v;
    }
    tt.services.push_back(s);
  }
  return tt;
}

Timetable LoadTimetable(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw InputError(path.string() + ": cannot read timetable file");
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  return ParseTimetable(ss.str(), path.string());
}

namespace {
[[noreturn]] void FailAt(const std::string& file, const std::string& entry, const std::string& reason) {
  throw InputError(file + ": " + entry + ": " + reason);
}
}  // namespace

void CheckTimetable(const Timetable& tt, const offline::Line& line, const std::map<std::string, TrainType>& trains) {
  if (tt.line != line.name) {
    FailAt(tt.file, "line", "timetable for line '" + tt.line + "', but the line file is '" + line.name + "' (" + line.file + ")");
  }
  for (std::size_t i = 0; i < tt.services.size(); ++i) {
    const Service& s = tt.services[i];
    const std::string entry = "services[" + std::to_string(i) + "] (" + s.id + ")";
    const auto tr = trains.find(s.train);
    if (tr == trains.end()) {
      std::string have;
      for (const auto& [k, v] : trains) {
        have += (have.empty() ? "" : ", ") + k;
        (void)v;
      }
      FailAt(tt.file, entry + ".train", "unknown train type '" + s.train + "' (known: " + have + ")");
    }
    const offline::RunningLine* rl = nullptr;
    for (const auto& r : line.running_lines) {
      if (r.id == s.running_line) {
        rl = &r;
      }
    }
    if (rl == nullptr) {
      FailAt(tt.file, entry + ".running_line", "unknown running line '" + s.running_line + "' of line " + line.name);
    }
    if (rl->stations.size() < 2) {
      FailAt(tt.file, entry + ".running_line", "running line '" + s.running_line + "' has fewer than two stations");
    }
    auto index_of = [&](const std::string& name, const std::string& where) -> std::size_t {
      for (std::size_t k = 0; k < rl->stations.size(); ++k) {
        if (rl->stations[k].name == name) {
          return k;
        }
      }
      std::string have;
      for (const auto& st : rl->stations) {
        have += (have.empty() ? "" : ", ") + st.name;
      }
      FailAt(tt.file, entry + "." + where,
             "station '" + name + "' has no stop on running line " + s.running_line + " (stops: " + have + ")");
    };
    const std::size_t from = s.from.empty() ? 0 : index_of(s.from, "from");
    const std::size_t to = s.to.empty() ? rl->stations.size() - 1 : index_of(s.to, "to");
    if (from >= to) {
      FailAt(tt.file, entry, "origin " + rl->stations[from].name + " is not before destination " + rl->stations[to].name + " on running line " +
                      s.running_line);
    }
    std::size_t prev = from;
    for (std::size_t k = 0; k < s.stops.size(); ++k) {
      const std::string where = "stops[" + std::to_string(k) + "]";
      const std::size_t idx = index_of(s.stops[k].station, where);
      if (idx <= from || idx >= to) {
        FailAt(tt.file, entry + "." + where, "stop at " + s.stops[k].station + " is not between the origin " + rl->stations[from].name +
                                      " and the destination " + rl->stations[to].name);
      }
      if (idx <= prev) {
        FailAt(tt.file, entry + "." + where, "stop at " + s.stops[k].station + " is not in running order (after " + rl->stations[prev].name +
                                      ")");
      }
      if (s.stops[k].dwell_ms < tt.driver.min_dwell_ms) {
        FailAt(tt.file, entry + "." + where, "dwell " + std::to_string(s.stops[k].dwell_ms / 1000) + " s at " + s.stops[k].station +
                                      " is below the minimum dwell " + std::to_string(tt.driver.min_dwell_ms / 1000) + " s");
      }
      prev = idx;
    }
    const TrainType& t = tr->second;
    auto check_platform = [&](std::size_t idx, const std::string& where) {
      const offline::Station& st = rl->stations[idx];
      if (st.stop_mm - t.length_mm < st.platform.begin_mm) {
        FailAt(tt.file, entry + "." + where, "train " + t.name + " (" + std::to_string(t.length_mm / 1000) + " m) does not fit platform " +
                                      st.name + " [" + std::to_string(st.platform.begin_mm) + ", " +
                                      std::to_string(st.platform.end_mm) + ") mm with its front at the stop " +
                                      std::to_string(st.stop_mm) + " mm");
      }
    };
    check_platform(from, "from");
    check_platform(to, "to");
    for (std::size_t k = 0; k < s.stops.size(); ++k) {
      check_platform(index_of(s.stops[k].station, "stops"), "stops[" + std::to_string(k) + "]");
    }
  }
}

}  // namespace railproof::lc::analysis
