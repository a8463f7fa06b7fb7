// Writing a result file of an offline tool atomically: the text goes to <path>.tmp, which
// is then renamed over <path>, so a reader (or the build) never sees a half-written file
// and a failed run leaves the previous file or none. Offline module; throws InputError.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

#include "railproof/offline/line.hpp"

namespace railproof::offline {

inline void WriteFileAtomic(const std::filesystem::path& path, const std::string& text) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) {
      throw InputError(path.string() + ": cannot write");
    }
    out << text;
    if (!out) {
      throw InputError(path.string() + ": write failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    throw InputError(path.string() + ": cannot write (" + ec.message() + ")");
  }
}

// A result JSON file of an offline tool (nlohmann::json or ordered_json), written atomically
// in the tools' one format: indented by one space, ending with a newline.
template <typename Json>
void WriteJsonFile(const std::filesystem::path& path, const Json& json) {
  WriteFileAtomic(path, json.dump(1) + "\n");
}

}  // namespace railproof::offline
