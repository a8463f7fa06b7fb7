// residual_error: rate of undetected erroneous telegrams of the link coding (REQ-TG-019).
// Prints a table and optionally writes JSON (results/analysis/residual_error.json in the
// pipeline). Defaults come from the generated parameters (spec/parameters/tg.yaml).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "railproof/tg/analysis/residual_error.hpp"
#include "railproof/generated/tg_params.hpp"
#include "railproof/tg/telegram.hpp"
#include "railproof/offline/cli.hpp"
#include "railproof/offline/output_file.hpp"

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

std::string Description() {
  char text[1024];
  std::snprintf(text, sizeof text,
                "Residual error of the telegram layer's link coding (REQ-TG-019): RS(n,k) over\n"
                "GF(2^m) with strict bounded-distance decoding, then CRC-16 (pass 2^-16), then the\n"
                "128-bit authentication tag (pass probability --tag-pass, default 2^-128).\n"
                "Per hour = P(undetected per telegram) x bit_rate / (blocks*n*m) x 3600.\n"
                "The defaults come from spec/parameters/tg.yaml; without --ber the two bit error\n"
                "rates D5 reports (%g and %g).",
                static_cast<double>(tg::design_ber), static_cast<double>(tg::comparison_ber));
  return text;
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
  std::vector<double> bers;
  std::string json_path;
  double tag_pass = std::ldexp(1.0, -128);

  namespace off = railproof::offline;
  off::Cli cli("residual_error", Description(), "Prints a table. Exit status: 0 done, 2 bad usage or input.");
  cli.Add("--ber", bers, "bit error probability in [0, 1]; repeatable")->check(off::InRange(0.0, 1.0));
  cli.Add("--bit-rate", config.bit_rate_bps, "channel bit rate (bit/s)")->check(off::Above(0.0));
  cli.Add("--n", config.code.n, "code length (symbols)");
  cli.Add("--k", config.code.k, "code dimension (symbols)");
  cli.Add("--m", config.code.m, "symbol bits, 2..8");
  cli.Add("--blocks", config.blocks, "RS blocks per frame (default: the longest frame)")->check(off::InRange(1, 1e9));
  cli.Add("--target", config.target_per_hour, "residual target per hour")->check(off::Above(0.0));
  cli.Add("--tag-pass", tag_pass, "probability that a wrong frame passes the tag")->check(off::InRange(0.0, 1.0));
  cli.Add("--json", json_path, "also write the results as JSON");
  cli.ParseOrExit(argc, argv);
  config.tag_pass = static_cast<long double>(tag_pass);
  if (bers.empty()) {  // the two bit error rates D5 reports (spec/parameters)
    bers.push_back(static_cast<double>(tg::design_ber));
    bers.push_back(static_cast<double>(tg::comparison_ber));
  }
  return off::RunTool("residual_error", [&] {
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
      off::WriteFileAtomic(path, railproof::tg::analysis::ResidualReportJson(config, results));
      std::cout << "wrote " << json_path << "\n";
    }
    return 0;
  });
}
