// Generator of the committed seed corpus of fuzz_frame_decode
// (cpp/runtime/tg/fuzz/corpus/frame_decode/): every catalogue telegram of fuzz_common.hpp as a
// valid frame, plus one seed per rejection path of checks 1-3 and 5 (design §4).
//
//   fuzz_make_corpus --out DIR        write the corpus files into DIR
//   fuzz_make_corpus --check DIR      exit 1 unless DIR holds exactly these files
//   fuzz_make_corpus --negative FILE  write an authentic frame under the fuzz key that is
//                                     NOT in the catalogue (the oracle must trap on it)
//
// Human-readable lines go to stderr, one JSON summary line to stdout. Offline tool.
#include <array>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fuzz_common.hpp"

namespace {

namespace fs = std::filesystem;
namespace rf = railproof::fuzz;
namespace rr = railproof::tg;

using Bytes = std::vector<std::uint8_t>;

struct Seed {
  std::string name;
  Bytes bytes;
  rr::RejectReason expect;  // verdict of DecodeFrame, then OpenPayload under the fuzz key
};

rr::RejectReason Verdict(const Bytes& bytes) {
  rr::DecodedFrame frame{};
  const rr::RejectReason decoded = rr::DecodeFrame(bytes, frame);
  if (decoded != rr::RejectReason::kNone) {
    return decoded;
  }
  std::array<std::uint8_t, rr::kPayloadMax> plain{};
  return rr::OpenPayload(frame, rf::FuzzKey(), plain);
}

rr::EncodedFrame EncodeEntry(const rf::CorpusTelegram& t, const rr::LinkKey& key) {
  rr::EncodedFrame frame{};
  if (rr::EncodeFrame(t.header, t.Payload(), key, frame) != rr::EncodeStatus::kOk) {
    throw std::runtime_error("EncodeFrame failed");
  }
  return frame;
}

Bytes ToBytes(const rr::EncodedFrame& frame) {
  const auto view = frame.View();
  return Bytes(view.begin(), view.end());
}

rr::InnerFrame InnerOf(const rr::EncodedFrame& frame) {
  rr::InnerFrame inner{};
  if (rr::CheckBlockDecoding(frame.View(), inner) != rr::RejectReason::kNone) {
    throw std::runtime_error("CheckBlockDecoding failed on a fresh frame");
  }
  return inner;
}

Bytes Reencode(const rr::InnerFrame& inner) {
  rr::EncodedFrame frame{};
  if (!rr::EncodeBlocks(inner.Data(), frame)) {
    throw std::runtime_error("EncodeBlocks failed");
  }
  return ToBytes(frame);
}

// Deterministic symbol errors: `errors` distinct positions of block `block`.
void Corrupt(Bytes& bytes, std::size_t block, std::size_t errors) {
  for (std::size_t j = 0; j < errors; ++j) {
    bytes.at(block * rr::kBlockBytes + (7 * j + 3) % rr::kBlockBytes) ^= static_cast<std::uint8_t>(0x5A + j);
  }
}

std::string Name(const char* stem, std::size_t len) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%s-L%03zu.bin", stem, len);
  return buf;
}

// Catalogue index of the entry with the given type and payload length.
std::size_t IndexOf(bool control, std::size_t len) {
  for (std::size_t i = 0; i < rf::kCorpusTelegrams; ++i) {
    const auto t = rf::CorpusEntry(i);
    if ((t.header.type == rr::TelegramType::kControl) == control && t.header.payload_len == len) {
      return i;
    }
  }
  throw std::logic_error("no catalogue entry with that length");
}

std::vector<Seed> BuildCorpus() {
  std::vector<Seed> seeds;
  const rr::LinkKey& key = rf::FuzzKey();
  for (std::size_t i = 0; i < rf::kCorpusTelegrams; ++i) {
    const auto t = rf::CorpusEntry(i);
    char buf[96];
    std::snprintf(buf, sizeof buf, "valid-%02zu-%s-L%03u.bin", i,
                  t.header.type == rr::TelegramType::kControl ? "control" : "position",
                  static_cast<unsigned>(t.header.payload_len));
    seeds.push_back({buf, ToBytes(EncodeEntry(t, key)), rr::RejectReason::kNone});
  }
  {  // check 1 passes after correcting t = 8 symbols in every block: accepted
    Bytes b = ToBytes(EncodeEntry(rf::CorpusEntry(IndexOf(true, 128)), key));
    for (std::size_t blk = 0; blk < b.size() / rr::kBlockBytes; ++blk) {
      Corrupt(b, blk, rf::kRsRadius);
    }
    seeds.push_back({Name("noisy-8-per-block", 128), b, rr::RejectReason::kNone});
  }
  {  // check 1: 9 symbol errors in block 1 -> RsUncorrectable
    Bytes b = ToBytes(EncodeEntry(rf::CorpusEntry(IndexOf(true, 61)), key));
    Corrupt(b, 1, rf::kRsRadius + 1);
    seeds.push_back({Name("rs-9-symbols-block1", 61), b, rr::RejectReason::kRsUncorrectable});
  }
  {  // check 1: 65 bytes -> BadLength
    Bytes b = ToBytes(EncodeEntry(rf::CorpusEntry(IndexOf(true, 0)), key));
    b.resize(rr::kBlockBytes - 1);
    seeds.push_back({"bad-length-65.bin", b, rr::RejectReason::kBadLength});
  }
  {  // check 2: version 2 -> BadFormat
    auto inner = InnerOf(EncodeEntry(rf::CorpusEntry(IndexOf(true, 0)), key));
    inner.bytes[rr::layout::kVersion] = 2;
    rf::FixCrc(inner, 0);
    seeds.push_back({Name("bad-format-version", 0), Reencode(inner), rr::RejectReason::kBadFormat});
  }
  {  // check 2: non-zero padding -> BadFormat
    auto inner = InnerOf(EncodeEntry(rf::CorpusEntry(IndexOf(true, 12)), key));
    inner.bytes[rr::FrameBytes(12) + 9] = 1;
    seeds.push_back({Name("bad-format-padding", 12), Reencode(inner), rr::RejectReason::kBadFormat});
  }
  {  // check 2: one block more than the length needs -> BadFormat
    Bytes b = ToBytes(EncodeEntry(rf::CorpusEntry(IndexOf(true, 61)), key));
    b.resize(b.size() + rr::kBlockBytes, 0);  // the all-zero word is a codeword
    seeds.push_back({Name("bad-format-block-count", 61), b, rr::RejectReason::kBadFormat});
  }
  {  // check 3: flipped CRC bit -> CrcMismatch
    auto inner = InnerOf(EncodeEntry(rf::CorpusEntry(IndexOf(true, 12)), key));
    inner.bytes[rr::layout::CrcOffset(12)] ^= 0x10;
    seeds.push_back({Name("crc-mismatch", 12), Reencode(inner), rr::RejectReason::kCrcMismatch});
  }
  {  // check 5: sealed with another key -> AuthFailed
    const rr::LinkKey attacker(rf::kAttackerKeyBytes);
    seeds.push_back({Name("wrong-key", 62), ToBytes(EncodeEntry(rf::CorpusEntry(IndexOf(false, 62)), attacker)),
                     rr::RejectReason::kAuthFailed});
  }
  {  // check 5: flipped ciphertext bit, CRC and RS recomputed -> AuthFailed
    auto inner = InnerOf(EncodeEntry(rf::CorpusEntry(IndexOf(true, 111)), key));
    inner.bytes[rr::layout::kPayload + 50] ^= 0x04;
    rf::FixCrc(inner, 111);
    seeds.push_back({Name("tampered-ciphertext", 111), Reencode(inner), rr::RejectReason::kAuthFailed});
  }
  {  // check 5: flipped time-stamp bit (associated data), CRC and RS recomputed -> AuthFailed
    auto inner = InnerOf(EncodeEntry(rf::CorpusEntry(IndexOf(false, 1)), key));
    inner.bytes[rr::layout::kTimestamp + 3] ^= 0x01;
    rf::FixCrc(inner, 1);
    seeds.push_back({Name("tampered-header", 1), Reencode(inner), rr::RejectReason::kAuthFailed});
  }
  for (const auto& seed : seeds) {  // each seed exercises the path its name promises
    if (Verdict(seed.bytes) != seed.expect) {
      throw std::logic_error(seed.name + ": verdict " + rr::ToString(Verdict(seed.bytes)) + ", expected " +
                             rr::ToString(seed.expect));
    }
  }
  return seeds;
}

// An authentic telegram under the fuzz key whose sequence number is outside the catalogue.
Bytes NegativeFrame() {
  auto t = rf::CorpusEntry(0);
  t.header.seq = rf::kCorpusSeqBase + static_cast<std::uint32_t>(rf::kCorpusTelegrams);
  Bytes bytes = ToBytes(EncodeEntry(t, rf::FuzzKey()));
  if (Verdict(bytes) != rr::RejectReason::kNone) {
    throw std::logic_error("negative frame is not authentic");
  }
  return bytes;
}

void WriteFile(const fs::path& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) {
    throw std::runtime_error("cannot write " + path.string());
  }
}

Bytes ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw std::runtime_error("cannot read " + path.string());
  }
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string Json(const fs::path& path) {
  std::string out;
  for (const char c : path.string()) {
    if (c == '"' || c == '\\') {
      out += '\\';
    }
    out += c;
  }
  return out;
}

void Usage(std::FILE* to) {
  std::fputs(
      "usage: fuzz_make_corpus (--out DIR | --check DIR | --negative FILE | --help)\n"
      "  --out DIR        write the seed corpus of fuzz_frame_decode into DIR\n"
      "  --check DIR      exit 1 unless DIR holds exactly the generated files\n"
      "  --negative FILE  write an authentic frame outside the corpus catalogue\n"
      "Prints one JSON summary line on stdout.\n",
      to);
}

int Run(const std::string_view mode, const fs::path& target) {
  if (mode == "--negative") {
    WriteFile(target, NegativeFrame());
    std::printf("{\"mode\":\"negative\",\"file\":\"%s\",\"status\":\"ok\"}\n", Json(target).c_str());
    return 0;
  }
  const auto seeds = BuildCorpus();
  if (mode == "--out") {
    fs::create_directories(target);
    for (const auto& s : seeds) {
      WriteFile(target / s.name, s.bytes);
    }
    std::fprintf(stderr, "fuzz_make_corpus: wrote %zu seeds to %s\n", seeds.size(), target.string().c_str());
    std::printf("{\"mode\":\"out\",\"dir\":\"%s\",\"files\":%zu,\"status\":\"ok\"}\n", Json(target).c_str(),
                seeds.size());
    return 0;
  }
  // --check
  std::size_t problems = 0;
  std::set<std::string> expected;
  for (const auto& s : seeds) {
    expected.insert(s.name);
    const fs::path path = target / s.name;
    if (!fs::exists(path)) {
      std::fprintf(stderr, "fuzz_make_corpus: missing %s\n", s.name.c_str());
      ++problems;
    } else if (ReadFile(path) != s.bytes) {
      std::fprintf(stderr, "fuzz_make_corpus: differs %s\n", s.name.c_str());
      ++problems;
    }
  }
  if (fs::is_directory(target)) {
    for (const auto& entry : fs::directory_iterator(target)) {
      if (expected.count(entry.path().filename().string()) == 0) {
        std::fprintf(stderr, "fuzz_make_corpus: unexpected %s\n", entry.path().filename().string().c_str());
        ++problems;
      }
    }
  }
  std::printf("{\"mode\":\"check\",\"dir\":\"%s\",\"files\":%zu,\"problems\":%zu,\"status\":\"%s\"}\n",
              Json(target).c_str(), seeds.size(), problems, problems == 0 ? "ok" : "mismatch");
  if (problems != 0) {
    std::fprintf(stderr, "fuzz_make_corpus: %zu problem(s): regenerate with --out\n", problems);
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string_view mode = argc > 1 ? argv[1] : "";
  if (mode == "--help" || mode == "-h") {
    Usage(stdout);
    return 0;
  }
  if (argc != 3 || (mode != "--out" && mode != "--check" && mode != "--negative")) {
    Usage(stderr);
    std::fprintf(stderr, "fuzz_make_corpus: expected one of --out DIR, --check DIR, --negative FILE\n");
    return 2;
  }
  try {
    return Run(mode, argv[2]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_make_corpus: %s\n", e.what());
    return 1;
  }
}
