// The keys of the br vector files besides those every vector file has (vector_file.hpp), as
// spec/schemas/vectors_br.schema.json defines them: the runner refuses any other key in a
// header, a vector or a step (the one shape of a step). A key added to
// the format is added here.
#pragma once

#include "railproof/testing/vector_file.hpp"

namespace railproof::conformance {

inline VectorKeys BrVectorKeys() {
  return VectorKeys{
      .header = KeyTree::parse(R"({
          "configuration": null, "units": null, "unit_scales": {"speed_mm_s_per_unit": null}, "parameters":
          {"model_vmax": null, "model_cycles": null, "levels": null}
      })"),
      .vector = KeyTree::object(),
      .step = KeyTree::parse(R"({
          "in": {"v_s": null, "v_e": null, "v_7n": null, "v_6n": null, "v_5n": null, "v_4n": null,
          "v_release": null, "standstill": null, "handle_emergency": null, "reset": null}, "out": {"level":
          null, "pattern_approaching": null, "emergency_latched": null}
      })")};
}

}  // namespace railproof::conformance
