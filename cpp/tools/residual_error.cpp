// residual_error: rate of undetected erroneous telegrams of the link coding (REQ-TG-019).
// Prints a table and optionally writes JSON (results/analysis/residual_error.json in the
// pipeline). Defaults come from the generated parameters (spec/parameters/telegram.yaml).
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "railproof/analysis/residual_error.hpp"
#include "railproof/generated/telegram_params.hpp"
#include "railproof/radio/telegram.hpp"

namespace {

namespace tg = railproof::params::telegram;
using railproof::analysis::ResidualConfig;
using railproof::analysis::ResidualResult;

// Default number of RS blocks per frame: that of the longest frame (design note §2:
// F = 39 + payload_max_bytes bytes in ceil(F / rs_k) blocks), from the radio module.
constexpr unsigned DefaultBlocks() { return static_cast<unsigned>(railproof::radio::kMaxBlocks); }

constexpr unsigned DefaultM() {
  unsigned m = 0;
  for (auto p = static_cast<unsigned>(tg::gf_primitive_poly); p > 1U; p >>= 1U) {
    ++m;
  }
  return m;
}

void PrintHelp() {
  std::printf(
      "usage: residual_error [--ber P]... [--bit-rate BPS] [--n N --k K --m M] [--blocks B]\n"
      "                      [--target RATE] [--tag-pass P] [--json FILE] [--help]\n"
      "\n"
      "Residual error of the telegram layer's link coding (REQ-TG-019): RS(n,k) over\n"
      "GF(2^m) with strict bounded-distance decoding, then CRC-16 (pass 2^-16), then the\n"
      "128-bit authentication tag (pass probability --tag-pass, default 2^-128).\n"
      "Per hour = P(undetected per telegram) x bit_rate / (blocks*n*m) x 3600.\n"
      "\n"
      "  --ber P        bit error probability in [0,1]; repeatable (default %g and %g)\n"
      "  --bit-rate BPS channel bit rate (default %g)\n"
      "  --n N --k K    code length and dimension (default %lld, %lld)\n"
      "  --m M          symbol bits, 2..8 (default %u)\n"
      "  --blocks B     RS blocks per frame (default %u, longest frame)\n"
      "  --target RATE  residual target per hour (default %g)\n"
      "  --tag-pass P   probability that a wrong frame passes the tag (default 2^-128)\n"
      "  --json FILE    also write the results as JSON\n",
      static_cast<double>(tg::design_ber), static_cast<double>(tg::comparison_ber),
      static_cast<double>(tg::radio_bit_rate_bps),
      static_cast<long long>(tg::rs_n),
      static_cast<long long>(tg::rs_k), DefaultM(), DefaultBlocks(),
      static_cast<double>(tg::residual_target_per_h));
}

[[noreturn]] void Fail(const std::string& reason) {
  std::fprintf(stderr, "residual_error: %s\n", reason.c_str());
  std::exit(2);
}

double ParseDouble(std::string_view opt, const char* text) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
    Fail(std::string(opt) + ": not a finite number: '" + text + "'");
  }
  return v;
}

unsigned ParseUnsigned(std::string_view opt, const char* text) {
  const std::string_view s(text);
  unsigned v = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || ptr != s.data() + s.size()) {
    Fail(std::string(opt) + ": not a non-negative integer: '" + text + "'");
  }
  return v;
}

}  // namespace

// @implements REQ-TG-019
int main(int argc, char** argv) {
  ResidualConfig config{};
  config.code = {static_cast<unsigned>(tg::rs_n), static_cast<unsigned>(tg::rs_k), DefaultM()};
  config.blocks = DefaultBlocks();
  config.bit_rate_bps = static_cast<double>(tg::radio_bit_rate_bps);
  config.target_per_hour = static_cast<double>(tg::residual_target_per_h);
  config.crc_pass = std::ldexp(1.0L, -16);
  config.tag_pass = std::ldexp(1.0L, -128);
  std::vector<double> bers;
  std::string json_path;

  for (int i = 1; i < argc; ++i) {
    const std::string_view opt(argv[i]);
    if (opt == "--help" || opt == "-h") {
      PrintHelp();
      return 0;
    }
    if (i + 1 >= argc) {
      Fail(std::string("unknown option or missing value: ") + argv[i]);
    }
    const char* val = argv[++i];
    if (opt == "--ber") {
      const double b = ParseDouble(opt, val);
      if (b < 0.0 || b > 1.0) {
        Fail("--ber must be in [0, 1], got " + std::string(val));
      }
      bers.push_back(b);
    } else if (opt == "--bit-rate") {
      config.bit_rate_bps = ParseDouble(opt, val);
      if (config.bit_rate_bps <= 0.0) {
        Fail("--bit-rate must be positive");
      }
    } else if (opt == "--n") {
      config.code.n = ParseUnsigned(opt, val);
    } else if (opt == "--k") {
      config.code.k = ParseUnsigned(opt, val);
    } else if (opt == "--m") {
      config.code.m = ParseUnsigned(opt, val);
    } else if (opt == "--blocks") {
      config.blocks = ParseUnsigned(opt, val);
      if (config.blocks < 1U) {
        Fail("--blocks must be >= 1");
      }
    } else if (opt == "--target") {
      config.target_per_hour = ParseDouble(opt, val);
      if (config.target_per_hour <= 0.0) {
        Fail("--target must be positive");
      }
    } else if (opt == "--tag-pass") {
      const double p = ParseDouble(opt, val);
      if (p < 0.0 || p > 1.0) {
        Fail("--tag-pass must be in [0, 1]");
      }
      config.tag_pass = static_cast<long double>(p);
    } else if (opt == "--json") {
      json_path = val;
    } else {
      Fail(std::string("unknown option: ") + argv[i - 1]);
    }
  }
  if (bers.empty()) {  // the two bit error rates D5 reports (spec/parameters)
    bers.push_back(static_cast<double>(tg::design_ber));
    bers.push_back(static_cast<double>(tg::comparison_ber));
  }

  try {
    railproof::analysis::ValidateCode(config.code);
    std::vector<ResidualResult> results;
    for (const double b : bers) {
      results.push_back(railproof::analysis::ComputeResidual(config, b));
    }
    std::cout << railproof::analysis::ResidualReportTable(config, results);
    if (!json_path.empty()) {
      const std::filesystem::path path(json_path);
      if (path.has_parent_path()) {
        std::filesystem::create_directories(path.parent_path());
      }
      std::ofstream out(path, std::ios::binary | std::ios::trunc);
      out << railproof::analysis::ResidualReportJson(config, results);
      out.close();
      if (!out) {
        Fail("cannot write " + json_path);
      }
      std::cout << "wrote " << json_path << "\n";
    }
  } catch (const std::exception& e) {
    Fail(e.what());
  }
  return 0;
}
