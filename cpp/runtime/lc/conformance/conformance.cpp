// railproof_conformance_lc: replays the vectors generated from models/lc.pml (every
// lc*.jsonl of the vector directory) against the C++ level-crossing units,
// spec/design/lc.md §3-§6: lc::onboard::CrossingProtection (railproof_onboard),
// lc::wayside::CrossingController and lc::wayside::CentreScheduler (railproof_wayside). One GoogleTest
// test per vector, named LevelCrossingConformance.<file>_<vector id>, plus
// LevelCrossingConformance.VectorSet, which fails if the vector set is missing, empty or
// malformed.
//
//   railproof_conformance_lc --vectors DIR [--junit FILE] [gtest flags]
//
// Each file's header gives the configuration of its vectors: the variant (ONBOARD: the
// on-board crossing function and one controller per crossing; GNSS: the centre scheduler and
// the controllers), the crossings, the train, the permitted-speed profile and every
// parameter (lc::onboard::ProtectionConfig, lc::wayside::ControllerConfig, lc::wayside::SchedulerConfig,
// the departure), all in mm, mm/s, mm/s², ms (header "unit_scales": a model tick is 10 s, a
// cell 100 m). Every vector starts from fresh units. Each step is one tick at t_ms; each unit
// is fed the step's inputs for it (not the other units' outputs: every unit is checked on its
// own) and must accept them:
//   ONBOARD  the controllers' cycles (requests, withdrawals, barrier detection), then the
//            on-board cycle (position, speed, dwell, the reports and acknowledgements received)
//   GNSS     the centre's cycle (acknowledgements, reports, the position report), then the
//            controllers' (start times, warning stops, clock, barrier detection)
// Expected: every output and state field of the step (controller state, warning start,
// report, acknowledgements, requesters, pending departure, clock, failure, lights, barrier
// command, no alarm; on-board crossing states, ETA class, requests, withdrawals, stop limit;
// centre messages, departure signal and its block, the per-crossing state). The model's
// ETA class eta2 = 2 floor(E) + (E not whole), E in ticks, is compared with the C++ eta_ms.
// On a mismatch the failure names the vector, the step, the unit, the field, expected and
// actual. A report lists the controller's requesters; the on-board unit is cleared only by a
// CLOSED report that lists it (design §3 item 3).
// Last line: "railproof-conformance-lc: all N vectors passed" or
// "railproof-conformance-lc: vectors mismatched: K of N" or "...: error: <reason>".
#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "railproof/br/patterns.hpp"
#include "railproof/lc/onboard/crossing_protection.hpp"
#include "railproof/lc/wayside/centre_scheduler.hpp"
#include "railproof/lc/wayside/crossing_controller.hpp"
#include "railproof/testing/jsonl_runner.hpp"
#include "vector_config.hpp"
#include "vector_keys.hpp"

namespace rcli = railproof::conformance;

namespace {

namespace ob = railproof::lc::onboard;
namespace ws = railproof::lc::wayside;
namespace br = railproof::br;
using json = nlohmann::json;

using railproof::lc::conformance::ConfigFromHeader;
using railproof::lc::conformance::FileConfig;
using railproof::lc::conformance::I;
using railproof::lc::conformance::Ids;
using railproof::lc::conformance::IsArr;
using railproof::lc::conformance::IsBool;
using railproof::lc::conformance::IsInt;
using railproof::lc::conformance::IsObj;
using railproof::lc::conformance::ReportOf;
using railproof::lc::conformance::ReportString;

constexpr const char* kUnits = "model tick = 10000 ms, model cell = 100000 mm (positions in half-cells)";
constexpr std::int64_t kTickMs = 10000;

std::map<std::string, FileConfig> g_configs;  // per file, from its header

// ---- step shape ------------------------------------------------------------------------------
bool IdsOk(const json& o, const char* k) {
  if (!IsArr(o, k)) {
    return false;
  }
  for (const json& x : o[k]) {
    if (!x.is_number_integer()) {
      return false;
    }
  }
  return true;
}

bool ReportOk(const json& r) {
  return r.is_object() && IsInt(r, "crossing_id") && r.contains("status") && r["status"].is_string() &&
         IsInt(r, "warning_start_ms") && IsInt(r, "issued_ms") && IsBool(r, "clock_fault") && IdsOk(r, "requesters") &&
         r["requesters"].size() <= railproof::messages::kMaxReportRequesters;
}

bool ControllerStepOk(const json& c, bool gnss) {
  if (!c.is_object() || !IsInt(c, "crossing_id") || !IsObj(c, "in") || !IsObj(c, "out")) {
    return false;
  }
  const json& in = c["in"];
  const json& out = c["out"];
  if (!IdsOk(in, "requests") || !IdsOk(in, "withdrawals") || !IsBool(in, "barrier_down") || !IsBool(in, "barrier_up")) {
    return false;
  }
  if (!out.contains("state") || !out["state"].is_string() || !out.contains("warning_start_ms") ||
      !(out["warning_start_ms"].is_null() || out["warning_start_ms"].is_number_integer()) || !IsObj(out, "report") ||
      !ReportOk(out["report"]) || !IsBool(out, "lights_on") || !IsBool(out, "barriers_down_commanded") ||
      !out.contains("failure") || !out["failure"].is_string()) {
    return false;
  }
  if (!gnss) {
    return IdsOk(out, "withdrawal_acks") && IdsOk(out, "requesters");
  }
  if (!IsArr(in, "start_times") || !IsArr(in, "warning_stops") || !in.contains("clock") || !in["clock"].is_string()) {
    return false;
  }
  for (const json& m : in["start_times"]) {
    if (!IsInt(m, "crossing_id") || !IsInt(m, "departure_id") || !IsInt(m, "start_ms")) {
      return false;
    }
  }
  for (const json& m : in["warning_stops"]) {
    if (!IsInt(m, "crossing_id") || !IsInt(m, "departure_id")) {
      return false;
    }
  }
  return IsArr(out, "start_acks") && IsArr(out, "stop_acks") && IsObj(out, "pending") && out.contains("clock") &&
         out["clock"].is_string();
}

bool StepWellFormed(const std::string& file, const json& step) {
  const bool gnss = g_configs.at(file).gnss;
  if (!step.is_object() || !IsInt(step, "t_ms") || !IsArr(step, "controllers") || step["controllers"].size() != 2 ||
      !IsObj(step, "train")) {
    return false;
  }
  for (const json& c : step["controllers"]) {
    if (!ControllerStepOk(c, gnss)) {
      return false;
    }
  }
  if (!gnss) {
    if (!IsObj(step, "onboard") || !IsObj(step["onboard"], "in") || !IsObj(step["onboard"], "out")) {
      return false;
    }
    const json& tr = step["train"];
    const json& in = step["onboard"]["in"];
    const json& out = step["onboard"]["out"];
    if (!IsInt(tr, "front_mm") || !IsInt(tr, "speed_mm_s") || !IsBool(tr, "dwell") || !IsInt(tr, "departure_ms") ||
        !IsArr(in, "reports") || !IsArr(in, "acks") || !IsArr(out, "states") || !IsArr(out, "eta_half_ticks") ||
        !IdsOk(out, "requests") || !IdsOk(out, "withdrawals") || !out.contains("stop_limit_mm")) {
      return false;
    }
    for (const json& r : in["reports"]) {
      if (!ReportOk(r)) {
        return false;
      }
    }
    for (const json& a : in["acks"]) {
      if (!IsInt(a, "crossing_id") || !IsInt(a, "train_id")) {
        return false;
      }
    }
    return true;
  }
  if (!IsObj(step, "centre") || !IsObj(step["centre"], "in") || !IsObj(step["centre"], "out")) {
    return false;
  }
  const json& in = step["centre"]["in"];
  const json& out = step["centre"]["out"];
  if (!IsArr(in, "start_acks") || !IsArr(in, "stop_acks") || !IsArr(in, "reports") || !in.contains("position") ||
      !IsBool(out, "departure_cleared") || !out.contains("block") || !IsArr(out, "start_times") ||
      !IsArr(out, "warning_stops") || !IsArr(out, "crossings")) {
    return false;
  }
  for (const json& a : in["start_acks"]) {
    if (!IsInt(a, "crossing_id") || !IsInt(a, "departure_id") || !IsInt(a, "start_ms") || !IsBool(a, "stored")) {
      return false;
    }
  }
  for (const json& r : in["reports"]) {
    if (!ReportOk(r)) {
      return false;
    }
  }
  const json& pos = in["position"];
  return pos.is_null() || (IsInt(pos, "train_id") && IsInt(pos, "time_ms") && IsInt(pos, "front_mm") &&
                           IsInt(pos, "rear_mm") && IsInt(pos, "speed_mm_s"));
}

// A file's header: the configuration of its vectors.
std::string Header(const std::string& file, const json& obj) {
  FileConfig cfg;
  if (std::string e = ConfigFromHeader(obj, cfg); !e.empty()) {
    return e;
  }
  g_configs[file] = cfg;
  return "";
}

// ---- comparison helpers -------------------------------------------------------------------
std::string Str(std::int64_t x) { return std::to_string(x); }
using rcli::Bool;
using rcli::Checker;
using rcli::OptInt;
ws::ClockInput ClockOf(const std::string& s) {
  if (s == "NO_GNSS") {
    return ws::ClockInput::kNoGnss;
  }
  if (s == "FAULT") {
    return ws::ClockInput::kFault;
  }
  return ws::ClockInput::kGnss;
}

// One controller cycle and the comparison of its outputs (both variants).
void StepController(ws::CrossingController& ctl, std::int64_t now, const json& c, bool gnss, Checker& chk) {
  const json& in = c.at("in");
  const json& out = c.at("out");
  std::vector<std::uint32_t> requests;
  std::vector<std::uint32_t> withdrawals;
  for (const json& x : in.at("requests")) {
    requests.push_back(x.get<std::uint32_t>());
  }
  for (const json& x : in.at("withdrawals")) {
    withdrawals.push_back(x.get<std::uint32_t>());
  }
  std::vector<ws::StartTimeMessage> starts;
  std::vector<ws::WarningStopMessage> stops;
  ws::ControllerInput ci;
  ci.now_ms = now;
  ci.requests = requests;
  ci.withdrawals = withdrawals;
  ci.barrier_down = in.at("barrier_down").get<bool>();
  ci.barrier_up = in.at("barrier_up").get<bool>();
  if (gnss) {
    for (const json& m : in.at("start_times")) {
      starts.push_back(ws::StartTimeMessage{static_cast<std::uint32_t>(I(m, "crossing_id")),
                                            static_cast<std::uint32_t>(I(m, "departure_id")), I(m, "start_ms")});
    }
    for (const json& m : in.at("warning_stops")) {
      stops.push_back(ws::WarningStopMessage{static_cast<std::uint32_t>(I(m, "crossing_id")),
                                             static_cast<std::uint32_t>(I(m, "departure_id"))});
    }
    ci.start_times = starts;
    ci.warning_stops = stops;
    ci.clock = ClockOf(in.at("clock").get<std::string>());
  }
  if (const ws::ControllerError e = ctl.Cycle(ci); e != ws::ControllerError::kNone) {
    chk.Fail(std::string("Cycle rejected the inputs: ") + ToString(e) + " [inputs " + in.dump() + "]");
    return;
  }
  const ws::ControllerStatus& s = ctl.Status();
  const ws::ControllerOutput& o = ctl.Output();
  chk.Expect("state", out.at("state").get<std::string>(), ToString(s.state));
  if (!out.at("warning_start_ms").is_null()) {
    chk.Expect("warning_start_ms", OptInt(out.at("warning_start_ms")), Str(s.warning_start_ms));
  }
  chk.Expect("report", ReportString(out.at("report")), ReportString(o.report));
  chk.Expect("lights_on", Bool(out.at("lights_on").get<bool>()), Bool(o.lights_on));
  chk.Expect("barriers_down_commanded", Bool(out.at("barriers_down_commanded").get<bool>()),
             Bool(o.barriers_down_commanded));
  chk.Expect("failure", out.at("failure").get<std::string>(), ToString(s.failure));
  chk.Expect("alarm", "false", Bool(o.alarm));
  if (!gnss) {
    chk.Expect("withdrawal_acks", Ids(out.at("withdrawal_acks")), Ids(o.WithdrawalAcks()));
    chk.Expect("requesters", Ids(out.at("requesters")), Ids(s.Requesters()));
    return;
  }
  std::string exp_acks;
  for (const json& a : out.at("start_acks")) {
    exp_acks += "{" + Str(I(a, "crossing_id")) + "," + Str(I(a, "departure_id")) + "," + Str(I(a, "start_ms")) + "," +
                Bool(a.at("stored").get<bool>()) + "}";
  }
  std::string act_acks;
  for (const ws::StartTimeAck& a : o.StartAcks()) {
    act_acks += "{" + Str(a.crossing_id) + "," + Str(a.departure_id) + "," + Str(a.start_ms) + "," + Bool(a.stored) + "}";
  }
  chk.Expect("start_acks", "[" + exp_acks + "]", "[" + act_acks + "]");
  std::string exp_stops;
  for (const json& a : out.at("stop_acks")) {
    exp_stops += "{" + Str(I(a, "crossing_id")) + "," + Str(I(a, "departure_id")) + "}";
  }
  std::string act_stops;
  for (const ws::WarningStopAck& a : o.StopAcks()) {
    act_stops += "{" + Str(a.crossing_id) + "," + Str(a.departure_id) + "}";
  }
  chk.Expect("stop_acks", "[" + exp_stops + "]", "[" + act_stops + "]");
  const json& p = out.at("pending");
  chk.Expect("pending.present", Bool(p.at("present").get<bool>()), Bool(s.pending.present));
  if (p.at("present").get<bool>() && s.pending.present) {
    chk.Expect("pending.departure_id", OptInt(p.at("departure_id")), Str(s.pending.departure_id));
    chk.Expect("pending.start_ms", OptInt(p.at("start_ms")), Str(s.pending.start_ms));
    chk.Expect("pending.active", Bool(p.at("active").get<bool>()), Bool(s.pending.active));
  }
  chk.Expect("clock", out.at("clock").get<std::string>(), ToString(s.clock));
}

// The model's ETA class of a C++ ETA (ms): 2 floor(E) + (E not whole), E in ticks; -1 if none.
std::string EtaClass(std::int64_t eta_ms) {
  if (eta_ms < 0) {
    return "null";
  }
  return Str(2 * (eta_ms / kTickMs) + (eta_ms % kTickMs != 0 ? 1 : 0));
}

// Fresh controllers of a file's crossings (their configurations were accepted with the header).
std::vector<ws::CrossingController> Controllers(const FileConfig& cfg) {
  std::vector<ws::CrossingController> ctls;
  for (const ws::ControllerConfig& cc : cfg.controllers) {
    ctls.push_back(*ws::CrossingController::Create(cc).controller);
  }
  return ctls;
}

// Calls replay(step, t_ms, "step k (t=... ms): ") for every step of v in order, until the
// first problem.
template <typename StepFn>
void ForEachStep(const rcli::JsonVector& v, const std::vector<std::string>& problems, StepFn&& replay) {
  for (std::size_t k = 0; k < v.steps.size() && problems.empty(); ++k) {
    const json& step = v.steps[k];
    const std::int64_t now = I(step, "t_ms");
    replay(step, now, "step " + std::to_string(k) + " (t=" + Str(now) + " ms): ");
  }
}

// A unit's setup call that returned `error`: a problem "<what>: <error>" unless kNone; true if so.
template <typename Error>
bool SetupFailed(Error error, const char* what, std::vector<std::string>& problems) {
  if (error == Error::kNone) {
    return false;
  }
  problems.push_back(std::string(what) + ": " + ToString(error));
  return true;
}

void ReplayOnboard(const rcli::JsonVector& v, const FileConfig& cfg, std::vector<std::string>& problems) {
  auto created = ob::CrossingProtection::Create(cfg.protection);
  if (SetupFailed(created.error, "CrossingProtection::Create", problems)) {
    return;
  }
  ob::CrossingProtection& prot = *created.protection;
  if (SetupFailed(prot.LoadCrossings(cfg.crossings), "LoadCrossings", problems)) {
    return;
  }
  std::vector<ws::CrossingController> ctls = Controllers(cfg);
  ForEachStep(v, problems, [&](const json& step, std::int64_t now, const std::string& at) {
    for (std::size_t c = 0; c < ctls.size(); ++c) {
      Checker chk(problems, at + "controller " + Str(cfg.crossings[c].id) + " ");
      StepController(ctls[c], now, step.at("controllers")[c], false, chk);
    }
    const json& tr = step.at("train");
    const json& in = step.at("onboard").at("in");
    const json& out = step.at("onboard").at("out");
    std::vector<ob::CrossingReport> reports;
    std::vector<ob::WithdrawalAck> acks;
    for (const json& r : in.at("reports")) {
      reports.push_back(ReportOf(r));
    }
    for (const json& a : in.at("acks")) {
      acks.push_back(ob::WithdrawalAck{static_cast<std::uint32_t>(I(a, "crossing_id")),
                                       static_cast<std::uint32_t>(I(a, "train_id"))});
    }
    ob::ProtectionInput pi;
    pi.now_ms = now;
    pi.front_mm = I(tr, "front_mm");
    pi.speed_mm_s = I(tr, "speed_mm_s");
    pi.dwell = tr.at("dwell").get<bool>();
    pi.departure_ms = I(tr, "departure_ms");
    pi.restrictions = cfg.restrictions;
    pi.reports = reports;
    pi.acks = acks;
    Checker chk(problems, at + "on-board ");
    if (const ob::ProtectionError e = prot.Cycle(pi); e != ob::ProtectionError::kNone) {
      chk.Fail(std::string("Cycle rejected the inputs: ") + ToString(e) + " [inputs " + tr.dump() + "]");
      return;
    }
    const auto entries = prot.Entries();
    for (std::size_t c = 0; c < entries.size() && c < out.at("states").size(); ++c) {
      const std::string name = "crossing " + Str(entries[c].data.id) + " ";
      chk.Expect(name + "state", out.at("states")[c].get<std::string>(), ToString(entries[c].state));
      chk.Expect(name + "eta class", OptInt(out.at("eta_half_ticks")[c]), EtaClass(entries[c].eta_ms));
    }
    const ob::ProtectionOutput& o = prot.Output();
    chk.Expect("requests", Ids(out.at("requests")), Ids(o.Requests()));
    chk.Expect("withdrawals", Ids(out.at("withdrawals")), Ids(o.Withdrawals()));
    chk.Expect("stop_limit_mm", OptInt(out.at("stop_limit_mm")), OptInt(o.stop_limit_mm));
  });
}

void ReplayGnss(const rcli::JsonVector& v, const FileConfig& cfg, std::vector<std::string>& problems) {
  auto created = ws::CentreScheduler::Create(cfg.scheduler);
  if (SetupFailed(created.error, "CentreScheduler::Create", problems)) {
    return;
  }
  ws::CentreScheduler& centre = *created.scheduler;
  if (SetupFailed(centre.StartDeparture(cfg.departure, cfg.crossings, cfg.restrictions, cfg.started_at_ms),
                  "StartDeparture", problems)) {
    return;
  }
  std::vector<ws::CrossingController> ctls = Controllers(cfg);
  ForEachStep(v, problems, [&](const json& step, std::int64_t now, const std::string& at) {
    const json& in = step.at("centre").at("in");
    const json& out = step.at("centre").at("out");
    std::vector<ws::StartTimeAck> sacks;
    std::vector<ws::WarningStopAck> stacks;
    std::vector<ob::CrossingReport> reports;
    for (const json& a : in.at("start_acks")) {
      sacks.push_back(ws::StartTimeAck{static_cast<std::uint32_t>(I(a, "crossing_id")),
                                       static_cast<std::uint32_t>(I(a, "departure_id")), I(a, "start_ms"),
                                       a.at("stored").get<bool>()});
    }
    for (const json& a : in.at("stop_acks")) {
      stacks.push_back(ws::WarningStopAck{static_cast<std::uint32_t>(I(a, "crossing_id")),
                                          static_cast<std::uint32_t>(I(a, "departure_id"))});
    }
    for (const json& r : in.at("reports")) {
      reports.push_back(ReportOf(r));
    }
    ws::SchedulerInput si;
    si.now_ms = now;
    si.start_acks = sacks;
    si.stop_acks = stacks;
    si.reports = reports;
    si.restrictions = cfg.restrictions;
    if (const json& p = in.at("position"); !p.is_null()) {
      si.position = ws::CentrePositionReport{static_cast<std::uint32_t>(I(p, "train_id")), I(p, "time_ms"), I(p, "front_mm"),
                                       I(p, "rear_mm"), I(p, "speed_mm_s")};
    }
    {
      Checker chk(problems, at + "centre ");
      if (const ws::SchedulerError e = centre.Cycle(si); e != ws::SchedulerError::kNone) {
        chk.Fail(std::string("Cycle rejected the inputs: ") + ToString(e) + " [inputs " + in.dump() + "]");
        return;
      }
      const ws::SchedulerOutput& o = centre.Output();
      chk.Expect("departure_cleared", Bool(out.at("departure_cleared").get<bool>()), Bool(o.departure_cleared));
      chk.Expect("block", out.at("block").get<std::string>(), ToString(o.block));
      std::string exp;
      for (const json& m : out.at("start_times")) {
        exp += "{" + Str(I(m, "crossing_id")) + "," + Str(I(m, "departure_id")) + "," + Str(I(m, "start_ms")) + "}";
      }
      std::string act;
      for (const ws::StartTimeMessage& m : o.StartTimes()) {
        act += "{" + Str(m.crossing_id) + "," + Str(m.departure_id) + "," + Str(m.start_ms) + "}";
      }
      chk.Expect("start_times", "[" + exp + "]", "[" + act + "]");
      exp.clear();
      act.clear();
      for (const json& m : out.at("warning_stops")) {
        exp += "{" + Str(I(m, "crossing_id")) + "," + Str(I(m, "departure_id")) + "}";
      }
      for (const ws::WarningStopMessage& m : o.WarningStops()) {
        act += "{" + Str(m.crossing_id) + "," + Str(m.departure_id) + "}";
      }
      chk.Expect("warning_stops", "[" + exp + "]", "[" + act + "]");
      for (const json& e : out.at("crossings")) {
        const ws::ScheduledCrossing* sc = centre.Find(static_cast<std::uint32_t>(I(e, "crossing_id")));
        const std::string name = "crossing " + Str(I(e, "crossing_id")) + " ";
        if (sc == nullptr) {
          chk.Fail(name + "not held by the scheduler");
          continue;
        }
        chk.Expect(name + "start_ms", Str(I(e, "start_ms")), Str(sc->start_ms));
        chk.Expect(name + "start_pending", Bool(e.at("start_pending").get<bool>()), Bool(sc->start_pending));
        chk.Expect(name + "acked", Bool(e.at("acked").get<bool>()), Bool(sc->acked));
        chk.Expect(name + "passed", Bool(e.at("passed").get<bool>()), Bool(sc->passed));
        chk.Expect(name + "stop_pending", Bool(e.at("stop_pending").get<bool>()), Bool(sc->stop_pending));
        chk.Expect(name + "stop_acked", Bool(e.at("stop_acked").get<bool>()), Bool(sc->stop_acked));
        chk.Expect(name + "clock_fault", Bool(e.at("clock_fault").get<bool>()), Bool(sc->clock_fault));
      }
    }
    for (std::size_t c = 0; c < ctls.size() && problems.empty(); ++c) {
      Checker chk(problems, at + "controller " + Str(cfg.crossings[c].id) + " ");
      StepController(ctls[c], now, step.at("controllers")[c], true, chk);
    }
  });
}

void Replay(const rcli::JsonVector& v, std::vector<std::string>& problems) {
  const FileConfig& cfg = g_configs.at(v.file);
  if (cfg.gnss) {
    ReplayGnss(v, cfg, problems);
  } else {
    ReplayOnboard(v, cfg, problems);
  }
}

}  // namespace

int main(int argc, char** argv) {
  return rcli::RunJsonVectors(
      {.prog = "railproof-conformance-lc",
       .suite = "LevelCrossingConformance",
       .description = "Replays every lc*.jsonl vector of DIR against the C++ level-crossing units\n"
                      "(lc::onboard::CrossingProtection, lc::wayside::CrossingController, "
                      "lc::wayside::CentreScheduler),\nconfigured by each file's header. Exit 0 only if every "
                      "vector matches.",
       .prefix = "lc",
       // the two level-crossing models: the on-board-requested warning and the GNSS-time crossings
       .models = {"models/lc.pml", "models/lc_gnss.pml"},
       .units = kUnits,
       .keys = rcli::LcVectorKeys(),
       .header = Header,
       .step_ok = StepWellFormed,
       .replay = Replay},
      argc, argv);
}
