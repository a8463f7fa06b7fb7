// railproof_conformance: replays the vectors generated from models/tg.pml against the
// C++ endpoint (spec/design/tg.md §7). One GoogleTest test per vector, named
// TelegramConformance.<vector id with non-alphanumerics as '_'>, plus
// TelegramConformance.VectorSet, which fails if the vector set is missing, empty or
// malformed (a conformance run over no vectors is a failure).
//
//   railproof_conformance --vectors DIR [--junit FILE] [gtest flags]
//
// On a mismatch the failure names the vector id, the step index, the field, the expected
// and the actual value. The last line is a summary:
//   "railproof-conformance-tg: all N vectors passed"
//   "railproof-conformance-tg: vectors mismatched: K of N"
//   "railproof-conformance-tg: error: <reason>"            (no usable vector set)
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "railproof/testing/runner_cli.hpp"
#include "railproof/tg/aead.hpp"
#include "railproof/tg/endpoint.hpp"
#include "railproof/tg/frame.hpp"
#include "railproof/tg/telegram.hpp"
#include "vector_reader.hpp"

namespace rcli = railproof::conformance;

namespace {

namespace rr = railproof::tg;
namespace rc = railproof::conformance;

// Keys of the conformance configuration (public test values).
constexpr std::array<std::uint8_t, rr::kKeyBytes> kLinkKeyBytes = {
    0x63, 0x6f, 0x6e, 0x66, 0x6f, 0x72, 0x6d, 0x61, 0x6e, 0x63, 0x65, 0x2d, 0x6c, 0x69, 0x6e, 0x6b,
    0x2d, 0x6b, 0x65, 0x79, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0a, 0x0b, 0x0c};
constexpr std::array<std::uint8_t, rr::kKeyBytes> kAttackerKeyBytes = {
    0x61, 0x74, 0x74, 0x61, 0x63, 0x6b, 0x65, 0x72, 0x2d, 0x6b, 0x65, 0x79, 0x2d, 0x6e, 0x6f, 0x74,
    0x2d, 0x74, 0x68, 0x65, 0x2d, 0x6c, 0x69, 0x6e, 0x6b, 0x2d, 0x6b, 0x65, 0x79, 0x21, 0x21, 0x21};

// design §7: integrity "corrupt" overwrites 9 symbols of RS block 0 (radius t = 8) with
// different values.
constexpr std::size_t kCorruptSymbols = 9;
constexpr std::size_t kCorruptStride = 7;
static_assert(kCorruptSymbols * kCorruptStride <= rr::kBlockBytes);

rc::VectorSet g_set;

struct Mismatch {
  std::size_t step;
  const char* ev;
  std::string field;
  std::string expected;
  std::string actual;
};

std::string Str(std::uint64_t v) { return std::to_string(v); }
std::string Str(bool v) { return v ? "true" : "false"; }
std::string Str(const std::optional<std::uint32_t>& v) { return v ? std::to_string(*v) : "null"; }
std::string Tracking(bool abnormal) { return abnormal ? "ABNORMAL" : "TRACKED"; }

class StepChecker {
 public:
  StepChecker(std::size_t step, const char* ev, std::vector<Mismatch>& out) : step_(step), ev_(ev), out_(out) {}
  template <typename T>
  void Field(const char* name, const T& expected, const T& actual) {
    if (!(expected == actual)) {
      out_.push_back(Mismatch{step_, ev_, name, Str(expected), Str(actual)});
    }
  }
  void Text(const char* name, const std::string& expected, const std::string& actual) {
    if (expected != actual) {
      out_.push_back(Mismatch{step_, ev_, name, expected, actual});
    }
  }
  void Outputs(const rc::Expected& e, rr::LinkState link, bool emergency_brake, bool tracking_abnormal) {
    Text("link", rr::ToString(e.link), rr::ToString(link));
    if (e.eb) {
      Field("eb", *e.eb, emergency_brake);
    }
    if (e.abnormal) {
      Text("tracking", Tracking(*e.abnormal), Tracking(tracking_abnormal));
    }
  }
 private:
  std::size_t step_;
  const char* ev_;
  std::vector<Mismatch>& out_;
};

rr::EndpointConfig ConfigFor(const rc::FileHeader& h, rr::Role role) {
  rr::EndpointConfig c = h.endpoint;
  c.role = role;
  c.own_id = role == rr::Role::kGround ? h.ground_id : h.train_id;
  c.peer_id = role == rr::Role::kGround ? h.train_id : h.ground_id;
  return c;
}

// Payload bytes of a delivered telegram (a fixed function of the step index).
std::array<std::uint8_t, 8> RxPayload(std::size_t step) {
  std::array<std::uint8_t, 8> p{};
  for (std::size_t i = 0; i < p.size(); ++i) {
    p[i] = static_cast<std::uint8_t>(0x30U + 11U * i + 7U * step);
  }
  return p;
}

// Replays one vector; returns the mismatches of the first diverging step (empty: passed).
std::vector<Mismatch> Replay(const rc::Vector& v, const rc::FileHeader& h, std::string& setup_error) {
  std::vector<Mismatch> mismatches;
  const rr::LinkKey link_key(kLinkKeyBytes);
  const rr::LinkKey attacker_key(kAttackerKeyBytes);
  rr::Endpoint ep;
  const rr::ConfigError config_error = ep.Init(ConfigFor(h, v.role), link_key);
  if (config_error != rr::ConfigError::kNone) {
    setup_error = std::string("the header parameters are rejected by Endpoint::Init: ") + rr::ToString(config_error);
    return mismatches;
  }
  std::uint64_t clock = 0;
  const std::array<std::uint8_t, 4> tick_payload = {0x54, 0x49, 0x43, 0x4b};
  for (std::size_t i = 0; i < v.steps.size() && mismatches.empty(); ++i) {
    const rc::Step& s = v.steps[i];
    if (s.kind == rc::Step::Kind::kTick) {
      clock += h.time_ms_per_tick;
      const auto now = static_cast<std::uint32_t>(clock);
      rr::EncodedFrame frame{};
      const auto out = ep.Cycle(now, tick_payload, frame);
      StepChecker check(i, "tick", mismatches);
      check.Text("status", rr::ToString(rr::SendStatus::kSent), rr::ToString(out.status));
      check.Field("tx.seq", std::uint64_t{s.out.tx_seq}, std::uint64_t{out.tx.seq});
      const std::optional<std::uint32_t> echo = out.tx.echo_valid ? std::optional<std::uint32_t>(out.tx.echo) : std::nullopt;
      check.Text("tx.echo", Str(s.out.tx_echo), Str(echo));
      check.Outputs(s.out, out.link, out.emergency_brake, out.tracking_abnormal);
      continue;
    }
    const auto now = static_cast<std::uint32_t>(clock);
    rr::TelegramHeader header{};
    header.version = rr::kVersion;
    header.type = s.tg.type;
    header.src = s.tg.src;
    header.dst = s.tg.dst;
    header.seq = s.tg.seq;
    header.echo = s.tg.echo.value_or(0U);
    header.echo_valid = s.tg.echo.has_value();
    header.timestamp_ms = now;
    const auto payload = RxPayload(i);
    rr::EncodedFrame frame{};
    if (rr::EncodeFrame(header, payload, s.tg.with_link_key ? link_key : attacker_key, frame) !=
        rr::EncodeStatus::kOk) {
      setup_error = "step " + std::to_string(i) + ": EncodeFrame failed";
      return mismatches;
    }
    if (s.tg.corrupt) {
      for (std::size_t k = 0; k < kCorruptSymbols; ++k) {
        frame.bytes[k * kCorruptStride] = static_cast<std::uint8_t>(frame.bytes[k * kCorruptStride] ^ 0xA5U);
      }
    }
    std::array<std::uint8_t, rr::kPayloadMax> payload_out{};
    const auto r = ep.Receive(now, frame.View(), payload_out);
    StepChecker check(i, "rx", mismatches);
    check.Text("verdict", rc::ToString(s.out.verdict), rc::ToString(rc::VerdictOf(r.reason)));
    check.Field("gap", std::uint64_t{s.out.gap}, std::uint64_t{r.gap});
    check.Outputs(s.out, r.link, r.emergency_brake, r.tracking_abnormal);
    if (r.reason == rr::RejectReason::kNone) {
      // The accepted content is exactly what was sent.
      header.payload_len = static_cast<std::uint16_t>(payload.size());
      check.Field("accepted header", true, r.header == header);
      check.Field("accepted payload", true, std::equal(payload.begin(), payload.end(), payload_out.begin()));
    } else {
      check.Field("rejected payload zeroed", true,
                  std::all_of(payload_out.begin(), payload_out.end(), [](std::uint8_t b) { return b == 0; }));
    }
  }
  return mismatches;
}

// Replays vector i: its requirements and goal are recorded with the test; a setup error or
// each mismatch of the first diverging step is a problem.
void ReplayVector(std::size_t i, std::vector<std::string>& problems) {
  const rc::Vector& v = g_set.vectors[i];
  std::string reqs;
  for (const auto& r : v.requirements) {
    reqs += (reqs.empty() ? "" : " ") + r;
  }
  testing::Test::RecordProperty("requirements", reqs);
  testing::Test::RecordProperty("goal", v.goal);
  std::string setup_error;
  const auto mismatches = Replay(v, g_set.headers[v.header_index], setup_error);
  if (!setup_error.empty()) {
    problems.push_back(setup_error);
    return;
  }
  for (const Mismatch& m : mismatches) {
    problems.push_back("step " + std::to_string(m.step) + " (" + m.ev + "): field " + m.field + ": expected " +
                       m.expected + ", actual " + m.actual);
  }
}

}  // namespace

int main(int argc, char** argv) {
  return rcli::RunnerMain(
      "railproof-conformance-tg", "TelegramConformance",
      "Replays every vector of DIR/*.jsonl (spec/design/tg.md §7) against the radio endpoint;\n"
      "one test per vector. Exit 0 only if the set is non-empty, well formed and every vector\n"
      "passes.",
      argc, argv,
      [](const std::string& dir) {
        rc::LoadResult loaded = rc::LoadVectorDirectory(dir);
        std::set<std::string> files;
        for (const auto& h : loaded.set.headers) {
          files.insert(h.file);
        }
        if (loaded.ok) {
          g_set = std::move(loaded.set);
        }
        return rcli::LoadedSet{loaded.ok, loaded.error, g_set.vectors.size(), files.size()};
      },
      [](std::size_t i) { return rcli::SiteOf(g_set.vectors, i); }, ReplayVector);
}
