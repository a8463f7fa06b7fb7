// The result files of one tool run, written all or none (output_file.hpp).
#include "railproof/offline/output_file.hpp"

#include <cerrno>
#include <cstdio>
#include <memory>
#include <system_error>
#include <utility>

#include "railproof/offline/line.hpp"

namespace railproof::offline {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void CannotWrite(const fs::path& path, const std::string& reason) {
  throw InputError(path.string() + ": cannot write: " + reason);
}

std::string Reason(int err) { return std::error_code(err, std::generic_category()).message(); }

// `text` into `tmp` (created or truncated); the reason on failure, empty on success.
std::string WriteWhole(const fs::path& tmp, std::string_view text) {
  errno = 0;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> out(std::fopen(tmp.c_str(), "wb"), &std::fclose);
  if (!out) {
    return Reason(errno);
  }
  if ((!text.empty() && std::fwrite(text.data(), 1, text.size(), out.get()) != text.size()) ||
      std::fflush(out.get()) != 0) {
    return Reason(errno != 0 ? errno : EIO);
  }
  if (std::fclose(out.release()) != 0) {
    return Reason(errno != 0 ? errno : EIO);
  }
  return {};
}

}  // namespace

OutputFiles::~OutputFiles() {
  if (committed_) {
    return;
  }
  std::error_code ec;
  for (auto& [key, f] : files_) {
    f.stream.reset();
    fs::remove(f.tmp, ec);
  }
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) {
    fs::remove(*it, ec);  // only if empty: what the run created and nothing else
  }
}

void OutputFiles::MakeDirectory(const fs::path& dir) {
  if (dir.empty()) {
    return;
  }
  // the missing directories, innermost first
  std::vector<fs::path> missing;
  std::error_code ec;
  for (fs::path d = dir; !d.empty() && !fs::exists(d, ec); d = d.parent_path()) {
    missing.push_back(d);
    if (d == d.parent_path()) {
      break;
    }
  }
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    if (fs::create_directory(*it, ec)) {
      created_.push_back(*it);
    } else if (ec) {
      throw InputError(dir.string() + ": cannot create the output directory: " + ec.message());
    }
  }
  if (!fs::is_directory(dir, ec)) {
    throw InputError(dir.string() + ": cannot create the output directory: " + (ec ? ec.message() : Reason(ENOTDIR)));
  }
}

void OutputFiles::Directory(const fs::path& dir) {
  const std::lock_guard<std::mutex> lock(mu_);
  MakeDirectory(dir);
}

OutputFiles::File& OutputFiles::Add(const fs::path& path) {
  std::error_code ec;
  const fs::path key = fs::absolute(path, ec).lexically_normal();
  if (path.empty() || !path.has_filename()) {
    CannotWrite(path, "not a file name");
  }
  if (files_.count(key) != 0) {
    CannotWrite(path, "two outputs of this run have this name");
  }
  if (fs::is_directory(path, ec)) {
    CannotWrite(path, Reason(EISDIR));
  }
  MakeDirectory(path.parent_path());
  File& f = files_[key];
  f.path = path;
  f.tmp = path;
  f.tmp += ".tmp";
  return f;
}

void OutputFiles::Reserve(const fs::path& path) {
  const std::lock_guard<std::mutex> lock(mu_);
  const File& f = Add(path);
  if (const std::string reason = WriteWhole(f.tmp, {}); !reason.empty()) {
    CannotWrite(path, reason);
  }
}

void OutputFiles::Write(const fs::path& path, std::string_view text) {
  fs::path tmp;
  {
    const std::lock_guard<std::mutex> lock(mu_);
    std::error_code ec;
    const auto it = files_.find(fs::absolute(path, ec).lexically_normal());
    if (it != files_.end() && (it->second.written || it->second.stream)) {
      CannotWrite(path, "two outputs of this run have this name");
    }
    File& f = it != files_.end() ? it->second : Add(path);
    f.written = true;
    tmp = f.tmp;
  }
  if (const std::string reason = WriteWhole(tmp, text); !reason.empty()) {
    CannotWrite(path, reason);
  }
}

std::ostream& OutputFiles::Stream(const fs::path& path) {
  const std::lock_guard<std::mutex> lock(mu_);
  File& f = Add(path);
  errno = 0;
  f.stream = std::make_unique<std::ofstream>(f.tmp, std::ios::binary);
  f.written = true;
  if (!*f.stream) {
    CannotWrite(path, errno != 0 ? Reason(errno) : std::string("cannot open"));
  }
  return *f.stream;
}

void OutputFiles::Commit() {
  const std::lock_guard<std::mutex> lock(mu_);
  for (auto& [key, f] : files_) {
    if (f.stream) {
      f.stream->close();
      if (!*f.stream) {
        CannotWrite(f.path, "write failed");
      }
    }
  }
  std::error_code ec;
  for (auto& [key, f] : files_) {
    if (!f.written) {
      fs::remove(f.tmp, ec);
      continue;
    }
    fs::rename(f.tmp, f.path, ec);
    if (ec) {
      CannotWrite(f.path, ec.message());
    }
    f.written = false;  // renamed: nothing left to remove
    f.tmp.clear();
  }
  committed_ = true;
}

}  // namespace railproof::offline
