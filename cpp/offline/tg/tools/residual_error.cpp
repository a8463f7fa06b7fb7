// residual_error: rate of undetected erroneous telegrams of the link coding (REQ-TG-019).
// Prints a table and optionally writes JSON (results/analysis/residual_error.json in the
// pipeline). Defaults come from the generated parameters (spec/parameters/tg.yaml).
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "railproof/tg/analysis/residual_error.hpp"
#include "railproof/generated/tg_params.hpp"
#include "railproof/tg/telegram.hpp"
#include "railproof/offline/cli.hpp"

namespace {

namespace tg = railproof::params::tg;
using railproof::tg::analysis::ResidualConfig;
using railproof::tg::analysis::ResidualResult;

// Default number of RS blocks per frame: that of the longest frame (design note §2:
// F = 39 + payload_max_bytes bytes in ceil(F / rs_k) blocks), from the radio module.
constexpr unsigned DefaultBlocks() { return static_cast<unsigned>(railproof::tg::kMaxBlocks); }

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

constexpr double kInf = std::numeric_limits<double>::infinity();

// A number of the command line (std::strtod, the whole text, finite, no range error).
railproof::offline::NumberRule Finite(double lo, double hi, bool lo_open, std::string range_message) {
  return {.lo = lo,
          .hi = hi,
          .lo_open = lo_open,
          .reject_range_error = true,
          .message = "{opt}: not a finite number: '{value}'",
          .range_message = std::move(range_message)};
}

// A count of the command line (digits only, fits an unsigned).
railproof::offline::IntegerRule Count(long long lo, std::string range_message) {
  return {.lo = lo,
          .digits_only = true,
          .message = "{opt}: not a non-negative integer: '{value}'",
          .range_message = std::move(range_message)};
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

  railproof::offline::CliParser cli(
      {.tool = "residual_error", .values = railproof::offline::CliStyle::Values::kPaired, .see_help = false}, PrintHelp);
  cli.Number("--ber", bers, Finite(0.0, 1.0, false, "--ber must be in [0, 1], got {value}"))
      .Number("--bit-rate", config.bit_rate_bps, Finite(0.0, kInf, true, "--bit-rate must be positive"))
      .Integer("--n", config.code.n, Count(0, ""))
      .Integer("--k", config.code.k, Count(0, ""))
      .Integer("--m", config.code.m, Count(0, ""))
      .Integer("--blocks", config.blocks, Count(1, "--blocks must be >= 1"))
      .Number("--target", config.target_per_hour, Finite(0.0, kInf, true, "--target must be positive"))
      .Number("--tag-pass", [&](double p) { config.tag_pass = static_cast<long double>(p); },
              Finite(0.0, 1.0, false, "--tag-pass must be in [0, 1]"))
      .Value("--json", json_path);
  cli.ParseOrExit(argc, argv);
  if (bers.empty()) {  // the two bit error rates D5 reports (spec/parameters)
    bers.push_back(static_cast<double>(tg::design_ber));
    bers.push_back(static_cast<double>(tg::comparison_ber));
  }

  try {
    railproof::tg::analysis::ValidateCode(config.code);
    std::vector<ResidualResult> results;
    for (const double b : bers) {
      results.push_back(railproof::tg::analysis::ComputeResidual(config, b));
    }
    std::cout << railproof::tg::analysis::ResidualReportTable(config, results);
    if (!json_path.empty()) {
      const std::filesystem::path path(json_path);
      if (path.has_parent_path()) {
        std::filesystem::create_directories(path.parent_path());
      }
      std::ofstream out(path, std::ios::binary | std::ios::trunc);
      out << railproof::tg::analysis::ResidualReportJson(config, results);
      out.close();
      if (!out) {
        cli.Fail("cannot write " + json_path);
      }
      std::cout << "wrote " << json_path << "\n";
    }
  } catch (const std::exception& e) {
    cli.Fail(e.what());
  }
  return 0;
}
