// The simulator tests' data: the test line (every kind of entry, tests/data/sim_test_line.json)
// and the files beside it, shared by the test files.
#pragma once

#include <filesystem>

#include "railproof/offline/line.hpp"

namespace railproof::sim {

inline std::filesystem::path DataDir() { return std::filesystem::path(__FILE__).parent_path() / "data"; }

inline const offline::Line& TestLine() {
  static const offline::Line line = offline::LoadLine(DataDir() / "sim_test_line.json");
  return line;
}

}  // namespace railproof::sim
