// Generated inputs of the analysis unit tests: the line and train JSON that the build writes
// from spec/ (build/gen/{lines,trains}; the build passes its directory as
// RAILPROOF_TEST_GEN_DIR, and the environment variable RAILPROOF_GEN_DIR overrides it).
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

#include "railproof/offline/train_type.hpp"

namespace railproof::testing {

using offline::LoadTrainType;
using offline::TrainType;

inline std::filesystem::path GenDir() {
  if (const char* env = std::getenv("RAILPROOF_GEN_DIR")) {
    return env;
  }
  return RAILPROOF_TEST_GEN_DIR;  // the build's gen directory (cpp/testing/CMakeLists.txt)
}

// A provided train type, or a negative-test type of spec/trains/mutants.
inline TrainType Train(const std::string& name) {
  const auto p = GenDir() / "trains" / (name + ".json");
  if (std::filesystem::exists(p)) {
    return LoadTrainType(p);
  }
  return LoadTrainType(GenDir() / "trains" / "mutants" / (name + ".json"));
}

}  // namespace railproof::testing
