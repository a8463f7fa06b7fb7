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

}  // namespace railproof::offline
