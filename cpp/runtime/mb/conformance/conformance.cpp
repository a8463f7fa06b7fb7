// railproof_conformance_mb: replays the vectors generated from models/mb.pml
// (every mb*.jsonl of the vector directory) against the C++ ground unit
// (railproof_wayside) and one on-board authority receiver per train (railproof_onboard),
// spec/design/mb.md §6. One GoogleTest test per vector, named
// MovingBlockConformance.<file>_<vector id>, plus MovingBlockConformance.VectorSet, which
// fails if the vector set is missing, empty or malformed.
//
//   railproof_conformance_mb --vectors DIR [--junit FILE] [gtest flags]
//
// Each vector starts from a fresh ground built from its file's header (the model's line:
// virtual blocks, platform as fixed block and set-back section, points with the automatic
// main route and the siding route, handover point, system boundary, margins, times) with
// the trains registered at their initial (provisional) positions at time 0. Steps:
//   cmd      -> the ground command; expected: possession state, siding requested
//   report   -> Ground::OnReport (front as block + offset); expected: accepted
//   tick     -> clock += tick_ms, Ground::Cycle; expected: every train's limit, kind and
//               tracking state and whether its on-board authority is still usable,
//               routes, points, possession, occupied blocks
//   deliver  -> AuthorityReceiver::Receive(limit, now - age, now); expected: verdict, the
//               on-board limit (null: nothing accepted yet)
// On a mismatch the failure names the vector, the step, the field, expected and actual.
// Last line: "railproof-conformance-mb: all N vectors passed" or
// "railproof-conformance-mb: vectors mismatched: K of N" or "...: error: <reason>".
#include <cstddef>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "railproof/mb/onboard/authority.hpp"
#include "railproof/mb/wayside/ground.hpp"
#include "railproof/testing/jsonl_runner.hpp"
#include "vector_keys.hpp"
#include "line_from_vector.hpp"

namespace rcli = railproof::conformance;

namespace {

namespace rw = railproof::mb::wayside;
namespace ro = railproof::mb::onboard;
using json = nlohmann::json;
using railproof::mb::wayside::test::LineData;
using railproof::mb::conformance::BuildLine;
using railproof::mb::conformance::kHandoverId;
using railproof::mb::conformance::kMainRouteId;
using railproof::mb::conformance::kSidingRouteId;
using railproof::mb::conformance::SectionOf;

struct Header {
  std::int64_t tick_ms = 0;
  json p;  // parameters
};

std::map<std::string, Header> g_headers;  // per file

// A file's header: the time scale and the parameters of its vectors.
std::string ReadHeader(const std::string& file, const json& obj) {
  const auto scales = obj.find("unit_scales");
  if (scales == obj.end() || !scales->is_object() || !scales->contains("time_ms_per_tick") ||
      !(*scales)["time_ms_per_tick"].is_number_integer()) {
    return "header unit_scales.time_ms_per_tick must be an integer";
  }
  Header h;
  h.tick_ms = (*scales)["time_ms_per_tick"].get<std::int64_t>();
  h.p = obj["parameters"];
  if (h.tick_ms <= 0) {
    return "unit_scales.time_ms_per_tick must be positive";
  }
  g_headers[file] = std::move(h);
  return "";
}

const char* PossessionName(rw::PossessionState s) {
  switch (s) {
    case rw::PossessionState::kNone: return "NONE";
    case rw::PossessionState::kRequested: return "REQUESTED";
    case rw::PossessionState::kActive: return "ACTIVE";
  }
  return "INVALID";
}

using rcli::Bool;
using rcli::OptInt;

void Replay(const rcli::JsonVector& v, std::vector<std::string>& problems) {
  const Header& h = g_headers.at(v.file);
  LineData d;
  BuildLine(h.p, h.tick_ms, d);
  const auto fronts = h.p.at("initial_front_mm").get<std::vector<std::int64_t>>();
  const auto corrs = h.p.at("initial_correction_mm").get<std::vector<std::int64_t>>();
  rw::Capacity cap = rw::DefaultCapacity();
  cap.trains = fronts.size();
  cap.blocks = d.blocks.size() - 1;
  auto created = rw::Ground::Create(d.Config(), cap, 0);
  if (created.error != rw::ConfigError::kNone) {
    problems.push_back(std::string("ground configuration refused: ") + ToString(created.error) +
                       " entry " + std::to_string(created.entry));
    return;
  }
  rw::Ground& g = *created.ground;
  const std::int64_t length = h.p.at("train_length_mm").get<std::int64_t>();
  std::vector<ro::AuthorityReceiver> onboard;
  const ro::AuthorityConfig acfg{h.p.at("validity_ms").get<std::int64_t>(), h.p.at("max_age_ms").get<std::int64_t>()};
  for (std::size_t t = 0; t < fronts.size(); ++t) {
    const auto st = g.RegisterTrain(rw::TrainRegistration{static_cast<std::uint32_t>(t), length, fronts[t], corrs[t],
                                                          rw::InitialPosition::kStabledProvisional});
    if (st != rw::RegisterStatus::kRegistered) {
      problems.push_back("train " + std::to_string(t) + " not registered");
      return;
    }
    onboard.emplace_back(acfg);
  }
  if (h.p.at("secured_at_start").get<bool>()) {
    for (std::size_t t = 0; t < fronts.size(); ++t) {
      g.SecureHandover(static_cast<std::uint32_t>(t), kHandoverId);
    }
  }
  if (h.p.at("boundary_accepted_at_start").get<bool>()) {
    g.AcceptAtBoundary(true);
  }
  std::optional<std::uint32_t> possession_id;
  std::int64_t now = 0;
  const auto& poss_range = h.p.at("possession_mm");
  for (std::size_t k = 0; k < v.steps.size() && problems.empty(); ++k) {
    const json& in = v.steps[k].at("in");
    const json& out = v.steps[k].at("out");
    const std::string ev = in.at("ev").get<std::string>();
    rcli::Checker chk(problems, "step " + std::to_string(k) + " (" + ev + "): ");
    if (ev == "cmd") {
      const std::string cmd = in.at("cmd").get<std::string>();
      if (cmd == "POSSESSION_REQUEST") {
        const auto r = g.RequestPossession(SectionOf(poss_range));
        if (r.status == rw::CommandStatus::kAccepted) {
          possession_id = r.id;
        }
      } else if (cmd == "POSSESSION_CANCEL") {
        if (possession_id) {
          g.CancelPossession(*possession_id);
        }
      } else if (cmd == "SIDING_REQUEST") {
        g.RequestRoute(kSidingRouteId);
      } else if (cmd == "SIDING_FREE") {
        chk.Expect("FreeRoute", "accepted",
                   g.FreeRoute(kSidingRouteId) == rw::CommandStatus::kAccepted ? "accepted" : "refused");
      } else if (cmd == "SECURE") {
        g.SecureHandover(in.at("train").get<std::uint32_t>(), kHandoverId);
      } else if (cmd == "BOUNDARY_ACCEPT") {
        g.AcceptAtBoundary(true);
      } else {
        problems.push_back("step " + std::to_string(k) + ": unknown command " + cmd);
        break;
      }
      const auto ps = possession_id ? g.Possession(*possession_id) : rw::PossessionState::kNone;
      chk.Expect("possession", out.at("possession").get<std::string>(), PossessionName(ps));
      chk.Expect("siding_requested", Bool(out.at("siding_requested").get<bool>()),
                 Bool(g.RouteRequested(kSidingRouteId)));
    } else if (ev == "report") {
      const auto t = in.at("train").get<std::uint32_t>();
      const std::int64_t front = in.at("front_mm").get<std::int64_t>();
      const auto loc = g.LocateFront(front);
      if (!loc) {
        problems.push_back("step " + std::to_string(k) + ": front " + std::to_string(front) + " not on the line");
        break;
      }
      rw::PositionReport r{};
      r.train_id = t;
      r.front_block = loc->block;
      r.offset_mm = loc->offset_mm;
      r.length_mm = length;
      r.correction_mm = in.at("correction_mm").get<std::int64_t>();
      r.last_balise_mm = 0;
      r.speed_mm_s = 0;
      r.direction = rw::Direction::kNominal;
      const auto st = g.OnReport(r);
      chk.Expect("tracked", out.at("tracked").get<bool>() ? "accepted" : "rejected",
                 st == rw::ReportStatus::kAccepted ? "accepted" : std::string("rejected ") + ToString(st));
    } else if (ev == "tick") {
      now += h.tick_ms;
      g.Cycle(now);
      const json& trains = out.at("trains");
      for (std::size_t t = 0; t < trains.size(); ++t) {
        const auto o = g.Train(static_cast<std::uint32_t>(t));
        const std::string pre = "train " + std::to_string(t) + " ";
        if (!o) {
          problems.push_back("step " + std::to_string(k) + ": " + pre + "unknown to the ground");
          continue;
        }
        chk.Expect(pre + "abnormal", Bool(trains[t].at("abnormal").get<bool>()), Bool(o->abnormal));
        chk.Expect(pre + "limit_mm", OptInt(trains[t].at("limit_mm")), OptInt(o->limit_mm));
        chk.Expect(pre + "kind", trains[t].at("kind").get<std::string>(), ToString(o->kind));
        // the on-board authority is still usable at this cycle (before its deliveries)
        chk.Expect(pre + "authority_usable", Bool(trains[t].at("authority_usable").get<bool>()),
                   Bool(onboard[t].Usable(now)));
      }
      chk.Expect("main_route", out.at("main_route").get<bool>() ? "set" : "unset",
                 g.RouteSet(kMainRouteId) ? "set" : "unset");
      chk.Expect("siding_route", out.at("siding_route").get<bool>() ? "set" : "unset",
                 g.RouteSet(kSidingRouteId) ? "set" : "unset");
      chk.Expect("points_reverse", Bool(out.at("points_reverse").get<bool>()), Bool(g.PointsReverse(0)));
      const auto ps = possession_id ? g.Possession(*possession_id) : rw::PossessionState::kNone;
      chk.Expect("possession", out.at("possession").get<std::string>(), PossessionName(ps));
      std::string occ_expected;
      for (const auto& b : out.at("occupied")) {
        occ_expected += std::to_string(b.get<std::int64_t>()) + " ";
      }
      std::string occ_actual;
      for (std::size_t b = 0; b < g.BlockCount(); ++b) {
        if (g.BlockOccupied(b)) {
          occ_actual += std::to_string(b) + " ";
        }
      }
      chk.Expect("occupied blocks", "[" + occ_expected + "]", "[" + occ_actual + "]");
    } else if (ev == "deliver") {
      const auto t = in.at("train").get<std::size_t>();
      if (t >= onboard.size()) {
        problems.push_back("step " + std::to_string(k) + ": unknown train " + std::to_string(t));
        break;
      }
      const std::int64_t issue = now - in.at("age_ms").get<std::int64_t>();
      const auto verdict = onboard[t].Receive(in.at("limit_mm").get<std::int64_t>(), issue, now);
      chk.Expect("verdict", out.at("verdict").get<std::string>(), ToString(verdict));
      chk.Expect("on-board limit_mm", OptInt(out.at("limit_mm")), OptInt(onboard[t].Limit()));
    } else {
      problems.push_back("step " + std::to_string(k) + ": unknown event " + ev);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  return rcli::RunJsonVectors(
      {.prog = "railproof-conformance-mb",
       .suite = "MovingBlockConformance",
       .description = "Replays every mb*.jsonl vector of DIR against the C++ ground and on-board units.",
       .prefix = "mb",
       .models = {"models/mb.pml"},
       .units = "",  // the header states none
       .keys = rcli::MbVectorKeys(),
       .header = ReadHeader,
       .step_ok = nullptr,  // the replay reads each step with at()
       .replay = Replay},
      argc, argv);
}
