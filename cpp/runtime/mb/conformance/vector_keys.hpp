// The keys of the mb vector files besides those every vector file has (vector_file.hpp), as
// spec/schemas/vectors_mb.schema.json defines them: the runner refuses any other key in a
// header, a vector or a step (the keys of every kind of step together: cmd, report, tick, deliver). A key added to
// the format is added here.
#pragma once

#include "railproof/testing/vector_file.hpp"

namespace railproof::conformance {

inline VectorKeys MbVectorKeys() {
  return VectorKeys{
      .header = KeyTree::parse(R"({
          "configuration": null, "unit_scales": {"time_ms_per_tick": null, "mm_per_unit": null}, "parameters":
          {"line_mm": null, "blocks_mm": null, "platform_mm": null, "points_mm": null, "route_main_mm": null,
          "possession_mm": null, "handover_mm": null, "boundary_mm": null, "margins_mm": null,
          "train_length_mm": null, "initial_front_mm": null, "initial_correction_mm": null,
          "tracking_timeout_ms": null, "validity_ms": null, "max_age_ms": null, "secured_at_start": null,
          "boundary_accepted_at_start": null}
      })"),
      .vector = KeyTree::object(),
      .step = KeyTree::parse(R"({
          "in": {"ev": null, "cmd": null, "train": null, "front_mm": null, "correction_mm": null, "limit_mm":
          null, "age_ms": null}, "out": {"possession": null, "siding_requested": null, "tracked": null,
          "trains": [{"limit_mm": null, "kind": null, "abnormal": null, "authority_usable": null}],
          "main_route": null, "siding_route": null, "points_reverse": null, "occupied": null, "verdict": null,
          "limit_mm": null}
      })")};
}

}  // namespace railproof::conformance
