// The pipeline's vector files as the on-board replays read them: every vector of the files
// <prefix>*.jsonl of the vector directory with its file's header, read with the conformance
// runners' reader and key lists.
#pragma once

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "railproof/testing/jsonl_vectors.hpp"

namespace railproof::units::test {

inline constexpr const char* kVectors = RAILPROOF_UNITS_VECTORS;

struct Loaded {
  std::vector<std::pair<std::string, nlohmann::json>> vectors;  // file, vector
  std::map<std::string, nlohmann::json> headers;
};

// The test fails on a missing, empty or unreadable set.
inline Loaded Load(const std::string& prefix, const conformance::VectorKeys& keys) {
  Loaded l;
  std::size_t files = 0;
  const std::string e = conformance::ReadVectorDirectory(
      kVectors, prefix, keys,
      [&](const std::string& file, const nlohmann::json& h) {
        l.headers[file] = h;
        return std::string();
      },
      [&](const conformance::VectorLineRef& v) {
        l.vectors.emplace_back(v.file, *v.obj);
        return std::string();
      },
      files);
  EXPECT_EQ(e, "");
  EXPECT_FALSE(l.vectors.empty()) << "no " << prefix << " vector in " << kVectors;
  return l;
}

}  // namespace railproof::units::test
