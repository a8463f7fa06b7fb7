// The keys of the ra vector files besides those every vector file has (vector_file.hpp), as
// spec/schemas/vectors_ra.schema.json defines them: the runner refuses any other key in a
// header, a vector or a step (the one shape of a step). A key added to
// the format is added here.
#pragma once

#include "railproof/testing/vector_file.hpp"

namespace railproof::conformance {

inline VectorKeys RaVectorKeys() {
  return VectorKeys{
      .header = KeyTree::parse(R"({
          "configuration": null, "units": null, "unit_scales": {"cycles_per_tick": null, "mm_per_margin_unit":
          null}, "parameters": {"confirm_cycles": null, "start_points": null, "spacing_cycles": null,
          "warmup_cycles": null, "start_age_cycles": null, "sections": [{"kind": null, "max_compensation_cycles": null, "margin_mm":
          null}], "model_cycles": null, "modes": null, "stop_reasons": null}
      })"),
      .vector = KeyTree::object(),
      .step = KeyTree::parse(R"({
          "in": {"deviation": null, "speed_agrees": null, "imu_ok": null, "tg_ok": null, "balise": null,
          "tg_moving": null, "section": {"kind": null, "max_compensation_cycles": null, "margin_mm": null}, "start_age_cycles":
          null}, "out": {"mode": null, "stop_reason": null, "deviation_count": null, "candidates": [{"active":
          null, "age_cycles": null, "confirm": null}], "max_compensation_cycles": null, "margin_mm": null,
          "stop_demand": null, "position_valid": null, "trusted": null, "rest_cycles": null, "detected": null,
          "adopted": null, "balise_reset": null}
      })")};
}

}  // namespace railproof::conformance
