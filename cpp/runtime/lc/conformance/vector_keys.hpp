// The keys of the lc vector files besides those every vector file has (vector_file.hpp), as
// spec/schemas/vectors_lc.schema.json defines them: the runner refuses any other key in a
// header, a vector or a step (the keys of the ONBOARD and the GNSS steps together). A key added to
// the format is added here.
#pragma once

#include "railproof/testing/vector_file.hpp"

namespace railproof::conformance {

inline VectorKeys LcVectorKeys() {
  return VectorKeys{
      .header = KeyTree::parse(R"({
          "configuration": null, "variant": null, "units": null, "unit_scales": {"ms_per_tick": null,
          "mm_per_cell": null, "mm_per_half_cell": null, "mm_s_per_speed_unit": null, "mm_s2_per_accel_unit":
          null}, "parameters": {"train": {"id": null, "length_mm": null, "accel_max_mm_s2": null},
          "other_train_id": null, "crossings": [{"id": null, "near_mm": null, "far_mm": null,
          "warning_time_ms": null}], "restrictions": [{"begin_mm": null, "end_mm": null, "limit_mm_s": null}],
          "protection": {"request_lead_ms": null, "confirmation_max_age_ms": null, "protection_offset_mm":
          null, "lookahead_mm": null}, "controller": {"barrier_lowering_ms": null, "barrier_timeout_ms": null,
          "max_warning_ms": null, "holdover_max_ms": null}, "station": {"front_mm": null, "dwell_ms": null},
          "scheduler": {"clock_allowance_ms": null}, "departure": {"train_id": null, "departure_id": null,
          "departure_ms": null, "front_mm": null, "started_at_ms": null}, "model_bounds": null,
          "controller_states": null, "onboard_states": null}
      })"),
      .vector = KeyTree::object(),
      .step = KeyTree::parse(R"({
          "t_ms": null, "controllers": [{"crossing_id": null, "in": {"requests": null, "withdrawals": null,
          "barrier_down": null, "barrier_up": null, "start_times": [{"crossing_id": null, "departure_id":
          null, "start_ms": null}], "warning_stops": [{"crossing_id": null, "departure_id": null}], "clock":
          null}, "out": {"state": null, "warning_start_ms": null, "report": {"crossing_id": null, "status":
          null, "warning_start_ms": null, "issued_ms": null, "clock_fault": null, "requesters": null},
          "withdrawal_acks": null, "requesters": null, "start_acks": [{"crossing_id": null, "departure_id":
          null, "start_ms": null, "stored": null}], "stop_acks": [{"crossing_id": null, "departure_id":
          null}], "pending": {"present": null, "departure_id": null, "start_ms": null, "active": null},
          "clock": null, "lights_on": null, "barriers_down_commanded": null, "failure": null}}], "train":
          {"front_mm": null, "speed_mm_s": null, "dwell": null, "departure_ms": null, "at_station": null},
          "onboard": {"in": {"reports": [{"crossing_id": null, "status": null, "warning_start_ms": null,
          "issued_ms": null, "clock_fault": null, "requesters": null}], "acks": [{"crossing_id": null,
          "train_id": null}]}, "out": {"states": null, "eta_half_ticks": null, "requests": null,
          "withdrawals": null, "stop_limit_mm": null}}, "centre": {"in": {"start_acks": [{"crossing_id": null,
          "departure_id": null, "start_ms": null, "stored": null}], "stop_acks": [{"crossing_id": null,
          "departure_id": null}], "reports": [{"crossing_id": null, "status": null, "warning_start_ms": null,
          "issued_ms": null, "clock_fault": null, "requesters": null}], "position": {"train_id": null,
          "time_ms": null, "front_mm": null, "rear_mm": null, "speed_mm_s": null}}, "out":
          {"departure_cleared": null, "block": null, "start_times": [{"crossing_id": null, "departure_id":
          null, "start_ms": null}], "warning_stops": [{"crossing_id": null, "departure_id": null}],
          "crossings": [{"crossing_id": null, "start_ms": null, "start_pending": null, "acked": null,
          "passed": null, "stop_pending": null, "stop_acked": null, "clock_fault": null}]}}
      })")};
}

}  // namespace railproof::conformance
