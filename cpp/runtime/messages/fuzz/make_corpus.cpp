// Generator of the committed seed corpus of fuzz_messages_decode (corpus/messages_decode/):
// every boundary message of the unit tests (tests/sample_messages.hpp) as valid-<name>.bin,
// and one payload per rejection reason as reject-<reason>-<what>.bin, each checked against
// the decoder's verdict its name promises.
//
//   fuzz_messages_make_corpus --out DIR     write the seeds into DIR
//   fuzz_messages_make_corpus --check DIR   exit 1 unless DIR holds exactly these seeds
//
// Human-readable lines go to stderr, one JSON summary line to stdout. Test tool (may allocate
// and throw).
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "../tests/sample_messages.hpp"
#include "railproof/messages/codec.hpp"

namespace {

namespace fs = std::filesystem;
namespace rm = railproof::messages;
using Bytes = std::vector<std::uint8_t>;

Bytes Encoded(const rm::Message& m) {
  const rm::Encoded e = rm::Encode(m);
  if (!e.Ok()) {
    throw std::logic_error(std::string("a sample does not encode: ") + rm::ToString(e.invalid));
  }
  const auto v = e.payload.View();
  return Bytes(v.begin(), v.end());
}

// A valid payload with bytes [at, at + patch.size()) replaced.
Bytes Patched(const rm::Message& m, std::size_t at, const Bytes& patch) {
  Bytes b = Encoded(m);
  for (std::size_t i = 0; i < patch.size(); ++i) {
    b.at(at + i) = patch[i];
  }
  return b;
}

// name -> (bytes, the decoder's verdict)
std::map<std::string, std::pair<Bytes, rm::DecodeError>> BuildCorpus() {
  namespace t = rm::test;
  std::map<std::string, std::pair<Bytes, rm::DecodeError>> seeds;
  for (const auto& s : t::BoundarySamples()) {
    seeds["valid-" + s.name + ".bin"] = {Encoded(s.message), rm::DecodeError::kNone};
  }
  const auto reject = [&seeds](const std::string& what, rm::DecodeError e, Bytes b) {
    std::string name = std::string("reject-") + rm::ToString(e) + "-" + what + ".bin";
    seeds[name] = {std::move(b), e};
  };
  Bytes short_position = Encoded(t::PositionMin());
  short_position.pop_back();
  Bytes swapped = Encoded(t::StopLimitMax());  // restrictions 0 and 1 exchanged
  std::swap_ranges(swapped.begin() + 24, swapped.begin() + 40, swapped.begin() + 40);
  reject("no-byte", rm::DecodeError::kEmpty, {});
  reject("type-0", rm::DecodeError::kUnknownType, {0});
  reject("type-10", rm::DecodeError::kUnknownType, Patched(t::PositionMax(), 0, {10}));
  reject("position-49-bytes", rm::DecodeError::kWrongLength, short_position);
  reject("7-restrictions", rm::DecodeError::kTooManyEntries, Patched(t::StopLimitMax(), 22, {7}));
  reject("17-requesters", rm::DecodeError::kTooManyEntries, Patched(t::ReportMax(), 23, {17}));
  reject("negative-offset", rm::DecodeError::kOutOfRange, Patched(t::PositionMin(), 9, {0xFF}));
  reject("restriction-speed-0", rm::DecodeError::kOutOfRange, Patched(t::StopLimitMax(), 36, {0, 0, 0, 0}));
  reject("obstruction-9", rm::DecodeError::kBadEnum, Patched(t::StopLimitMin(), 13, {9}));
  reject("status-4", rm::DecodeError::kBadEnum, Patched(t::ReportMin(), 5, {4}));
  reject("truncated-2", rm::DecodeError::kBadFlag, Patched(t::StopLimitMin(), 23, {2}));
  reject("clock-fault-2", rm::DecodeError::kBadFlag, Patched(t::ReportMin(), 22, {2}));
  reject("restriction-end-at-begin", rm::DecodeError::kEmptyRange,
         Patched(t::StopLimitMax(), 32, {0x80, 0, 0, 0}));
  reject("rear-ahead", rm::DecodeError::kEmptyRange, Patched(t::CentreMin(), 28, {0x02}));
  reject("restrictions-swapped", rm::DecodeError::kUnsorted, swapped);
  // bundles (checked with DecodeBundle below): a position report with a crossing request and a
  // withdrawal, the same with a bad count, and cut inside its last entry
  const std::array<rm::Message, 3> uplink = {rm::Message{t::PositionMax()}, rm::Message{rm::CrossingRequest{7, 3}},
                                             rm::Message{rm::CrossingWithdrawal{{7, 4}}}};
  const rm::Encoded bundle = rm::EncodeBundle(uplink);
  const Bytes bundle_bytes(bundle.payload.View().begin(), bundle.payload.View().end());
  Bytes bad_count = bundle_bytes;
  bad_count[1] = 1;
  Bytes oversized = {rm::kBundleType, 3};  // three position reports: more than a telegram carries
  for (int i = 0; i < 3; ++i) {
    const Bytes report = Encoded(t::PositionMax());
    oversized.push_back(static_cast<std::uint8_t>(report.size()));
    oversized.insert(oversized.end(), report.begin(), report.end());
  }
  std::map<std::string, std::pair<Bytes, rm::DecodeError>> bundles;
  bundles["reject-bundle-WRONG_LENGTH-oversized.bin"] = {oversized, rm::DecodeError::kWrongLength};
  bundles["valid-bundle-uplink.bin"] = {bundle_bytes, rm::DecodeError::kNone};
  bundles["reject-bundle-TOO_MANY_ENTRIES-count-1.bin"] = {bad_count, rm::DecodeError::kTooManyEntries};
  bundles["reject-bundle-WRONG_LENGTH-cut.bin"] = {Bytes(bundle_bytes.begin(), bundle_bytes.end() - 1),
                                                   rm::DecodeError::kWrongLength};
  for (const auto& [name, seed] : seeds) {  // each seed takes the path its name promises
    if (rm::Decode(seed.first).error != seed.second) {
      throw std::logic_error(name + ": the decoder says " + rm::ToString(rm::Decode(seed.first).error));
    }
  }
  for (const auto& [name, seed] : bundles) {
    if (rm::DecodeBundle(seed.first).error != seed.second) {
      throw std::logic_error(name + ": the bundle decoder says " + rm::ToString(rm::DecodeBundle(seed.first).error));
    }
    seeds[name] = seed;
  }
  return seeds;
}

bool SameFile(const fs::path& path, const Bytes& bytes) {
  std::ifstream in(path, std::ios::binary);
  return in && Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()) == bytes;
}

int Run(const std::string& mode, const fs::path& dir) {
  const auto seeds = BuildCorpus();
  std::size_t problems = 0;
  if (mode == "--out") {
    fs::create_directories(dir);
    for (const auto& [name, seed] : seeds) {
      std::ofstream out(dir / name, std::ios::binary | std::ios::trunc);
      out.write(reinterpret_cast<const char*>(seed.first.data()), static_cast<std::streamsize>(seed.first.size()));
      if (!out) {
        throw std::runtime_error("cannot write " + (dir / name).string());
      }
    }
  } else {
    for (const auto& [name, seed] : seeds) {
      if (!fs::is_regular_file(dir / name) || !SameFile(dir / name, seed.first)) {
        std::fprintf(stderr, "fuzz_messages_make_corpus: %s is missing or differs\n", name.c_str());
        ++problems;
      }
    }
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (seeds.count(entry.path().filename().string()) == 0) {
        std::fprintf(stderr, "fuzz_messages_make_corpus: %s is not generated\n", entry.path().string().c_str());
        ++problems;
      }
    }
  }
  std::fprintf(stderr, "fuzz_messages_make_corpus: %s %s: %zu seeds, %zu problems\n", mode.c_str(),
               dir.string().c_str(), seeds.size(), problems);
  std::printf("{\"mode\":\"%s\",\"seeds\":%zu,\"problems\":%zu}\n", mode.substr(2).c_str(), seeds.size(), problems);
  return problems == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc == 3 ? argv[1] : "";
  if (mode != "--out" && mode != "--check") {
    std::fputs("fuzz_messages_make_corpus: usage: fuzz_messages_make_corpus (--out DIR | --check DIR)\n", stderr);
    return 2;
  }
  try {
    return Run(mode, argv[2]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_messages_make_corpus: %s\n", e.what());
    return 2;
  }
}
