// The moving-block vectors (every mb*.jsonl of the pipeline's vector directory, read with the
// conformance runners' reader and keys) replayed through the wayside unit's external interface:
// each report enters as the bytes of a telegram from the train's end of its link, each
// expected stop limit is read from the bytes the unit sends the train, decoded there.
//   cmd     -> the unit's commands; expected: possession state, siding requested (ground view)
//   report  -> Receive(bytes of a POSITION telegram); expected: the report accepted or not
//   tick    -> Cycle; expected per train: tracking (the unit's train status), and for a tracked
//              train the limit and kind of the stop-limit telegram decoded from its frame (an
//              abnormal train gets a keep-alive); routes, points, possession, occupied blocks
//              (the ground's outputs, which the unit shows as they are)
// Not expressible through the wayside unit: `deliver` steps and `authority_usable` (the
// on-board authority receiver, train side) and an abnormal train's frozen bound (the ground
// keeps it, the train gets only a keep-alive). The link: before the vector starts, one cycle
// with the trains admitted but not yet registered brings the links up (the model's ground runs
// no cycle at time 0; with no train registered that cycle only sets the automatic route, which
// the model's first cycle sets too, no train standing on its points); after every tick each
// train answers with a NO_POSITION telegram, as an on-board unit without a report due does, so
// that the next control telegram echoes it within the turnaround.
#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mb/conformance/line_from_vector.hpp"
#include "mb/conformance/vector_keys.hpp"
#include "railproof/testing/jsonl_runner.hpp"
#include "wayside_test_support.hpp"

namespace railproof::units::test {
namespace {

namespace rc = railproof::conformance;
using json = nlohmann::json;

using mb::conformance::BuildLine;
using mb::conformance::kHandoverId;
using mb::conformance::kMainRouteId;
using mb::conformance::kSidingRouteId;
using mb::conformance::SectionOf;

struct MbRig {
  mb::wayside::test::LineData line;
  std::unique_ptr<WaysideUnit> unit;
  std::vector<TrainRadio> radios;
  std::int64_t length = 0;
  std::int64_t now = 0;
};

// Replays one mb vector through a fresh unit; the problems found (empty: it passed).
void ReplayMb(const json& header, const rc::JsonVector& v, std::vector<std::string>& problems) {
  const json& p = header.at("parameters");
  const std::int64_t tick = header.at("unit_scales").at("time_ms_per_tick").get<std::int64_t>();
  MbRig rig;
  BuildLine(p, tick, rig.line);
  WaysideConfig c = BaseConfig(rig.line);
  c.secure_ahead_mm.reset();  // the vectors secure the handover point by command
  c.line.ground_cycle_ms = tick;
  rig.unit = std::move(WaysideUnit::Create(c).unit);
  if (!rig.unit) {
    problems.push_back("unit configuration refused");
    return;
  }
  WaysideUnit& u = *rig.unit;
  const auto fronts = p.at("initial_front_mm").get<std::vector<std::int64_t>>();
  const auto corrs = p.at("initial_correction_mm").get<std::vector<std::int64_t>>();
  rig.length = p.at("train_length_mm").get<std::int64_t>();
  for (std::uint32_t t = 0; t < fronts.size(); ++t) {
    rig.radios.emplace_back(t, static_cast<std::uint16_t>(t + 10), 1);
    (void)u.Admit(t, static_cast<std::uint16_t>(t + 10));
  }
  const CycleOutput& first = u.Cycle(0, {});
  for (std::uint32_t t = 0; t < fronts.size(); ++t) {
    (void)rig.radios[t].Take(0, first);
    const auto r = u.Register({t, rig.length, fronts[t], corrs[t], mb::wayside::InitialPosition::kStabledProvisional});
    if (r.status != RegisterStatus::kRegistered) {
      problems.push_back("train " + std::to_string(t) + " not registered");
      return;
    }
    (void)u.Receive(0, t, rig.radios[t].Send(0, {messages::NoPosition{}}));
    if (p.at("secured_at_start").get<bool>()) {
      (void)u.SecureHandover(t, kHandoverId);
    }
  }
  if (p.at("boundary_accepted_at_start").get<bool>()) {
    (void)u.AcceptAtBoundary(true);
  }
  std::optional<std::uint32_t> possession;
  for (std::size_t k = 0; k < v.steps.size() && problems.empty(); ++k) {
    const json& in = v.steps[k].at("in");
    const json& out = v.steps[k].at("out");
    const std::string ev = in.at("ev").get<std::string>();
    rc::Checker chk(problems, "step " + std::to_string(k) + " (" + ev + "): ");
    const auto possession_state = [&] {
      return ToString(possession ? u.Ground().Possession(*possession) : mb::wayside::PossessionState::kNone);
    };
    if (ev == "cmd") {
      const std::string cmd = in.at("cmd").get<std::string>();
      if (cmd == "POSSESSION_REQUEST") {
        const auto r = u.RequestPossession(SectionOf(p.at("possession_mm")));
        if (r.status == mb::wayside::CommandStatus::kAccepted) {
          possession = r.id;
        }
      } else if (cmd == "POSSESSION_CANCEL" && possession) {
        (void)u.CancelPossession(*possession);
      } else if (cmd == "SIDING_REQUEST") {
        (void)u.RequestRoute(kSidingRouteId);
      } else if (cmd == "SIDING_FREE") {
        (void)u.FreeRoute(kSidingRouteId);
      } else if (cmd == "SECURE") {
        (void)u.SecureHandover(in.at("train").get<std::uint32_t>(), kHandoverId);
      } else if (cmd == "BOUNDARY_ACCEPT") {
        (void)u.AcceptAtBoundary(true);
      }
      chk.Expect("possession", out.at("possession").get<std::string>(), possession_state());
      chk.Expect("siding_requested", rc::Bool(out.at("siding_requested").get<bool>()),
                 rc::Bool(u.Ground().RouteRequested(kSidingRouteId)));
    } else if (ev == "report") {
      const auto t = in.at("train").get<std::uint32_t>();
      const auto r = u.Receive(rig.now, t,
                               rig.radios[t].Send(rig.now, {ReportAt(u, t, in.at("front_mm").get<std::int64_t>(),
                                                                     rig.length, in.at("correction_mm").get<std::int64_t>())}));
      const bool accepted = r.status == FrameStatus::kAccepted && r.message_count == 1 &&
                            r.messages[0].status == MessageStatus::kAccepted;
      chk.Expect("tracked", out.at("tracked").get<bool>() ? "accepted" : "rejected",
                 accepted ? "accepted"
                          : std::string("rejected ") + ToString(r.status) + "/" + ToString(r.tg_reason) + "/" +
                                ToString(r.messages[0].report));
    } else if (ev == "tick") {
      rig.now += tick;
      const CycleOutput& o = u.Cycle(rig.now, {});
      const json& trains = out.at("trains");
      for (std::uint32_t t = 0; t < trains.size(); ++t) {
        const std::string pre = "train " + std::to_string(t) + " ";
        const auto bundle = rig.radios[t].Take(rig.now, o);
        const bool abnormal = o.trains[t].abnormal;
        chk.Expect(pre + "abnormal", rc::Bool(trains[t].at("abnormal").get<bool>()), rc::Bool(abnormal));
        const auto* tel = StopLimitOf(bundle);
        if (abnormal) {
          chk.Expect(pre + "telegram", "KEEP_ALIVE",
                     bundle.size > 0 ? messages::ToString(messages::TypeOf(bundle.messages[0])) : "none");
        } else if (tel == nullptr) {
          chk.Fail(pre + "no stop-limit telegram in its frame (" + ToString(rig.radios[t].LastReason()) + ")");
        } else {
          chk.Expect(pre + "addressee", std::to_string(t), std::to_string(tel->train_id));
          chk.Expect(pre + "limit_mm", rc::OptInt(trains[t].at("limit_mm")), std::to_string(tel->limit_mm));
          chk.Expect(pre + "kind", trains[t].at("kind").get<std::string>(), ToString(tel->kind));
        }
        (void)u.Receive(rig.now, t, rig.radios[t].Send(rig.now, {messages::NoPosition{}}));
      }
      const auto& g = u.Ground();
      chk.Expect("main_route", rc::Bool(out.at("main_route").get<bool>()), rc::Bool(g.RouteSet(kMainRouteId)));
      chk.Expect("siding_route", rc::Bool(out.at("siding_route").get<bool>()), rc::Bool(g.RouteSet(kSidingRouteId)));
      chk.Expect("points_reverse", rc::Bool(out.at("points_reverse").get<bool>()), rc::Bool(g.PointsReverse(0)));
      chk.Expect("possession", out.at("possession").get<std::string>(), possession_state());
      std::string expected;
      for (const json& b : out.at("occupied")) {
        expected += std::to_string(b.get<std::int64_t>()) + " ";
      }
      std::string actual;
      for (std::size_t b = 0; b < g.BlockCount(); ++b) {
        actual += g.BlockOccupied(b) ? std::to_string(b) + " " : "";
      }
      chk.Expect("occupied", expected, actual);
    }
  }
}

// Reads the mb vectors and replays each; the vector set must be there and non-empty.
TEST(WaysideReplay, MovingBlockVectorsThroughTheUnitsBytes) {
  std::map<std::string, json> headers;
  std::vector<rc::JsonVector> vectors;
  std::size_t files = 0;
  const std::string error = rc::ReadVectorDirectory(
      RAILPROOF_UNITS_VECTORS, "mb", rc::MbVectorKeys(),
      [&](const std::string& file, const json& h) {
        headers[file] = h;
        return std::string();
      },
      [&](const rc::VectorLineRef& line) {
        vectors.push_back(rc::JsonVector{line.id, line.test_name, line.file, line.line, (*line.obj)["steps"]});
        return std::string();
      },
      files);
  ASSERT_EQ(error, "");
  ASSERT_GT(vectors.size(), 50U);
  std::size_t failed = 0;
  for (const rc::JsonVector& v : vectors) {
    std::vector<std::string> problems;
    ReplayMb(headers.at(v.file), v, problems);
    if (!problems.empty()) {
      ++failed;
      ADD_FAILURE() << v.file << " " << v.id << ": " << problems.front();
    }
  }
  EXPECT_EQ(failed, 0U) << "of " << vectors.size();
}

}  // namespace
}  // namespace railproof::units::test
