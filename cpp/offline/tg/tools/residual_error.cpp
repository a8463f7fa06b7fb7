// residual_error: rate of undetected erroneous telegrams of the link coding (REQ-TG-019).
// Prints a table and optionally writes JSON (results/analysis/residual_error.json in the
// pipeline). Defaults come from the generated parameters (spec/parameters/tg.yaml).
#include <cmath>
#include <cstdio>
#include <stdexcept>
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

struct Options {
  ResidualConfig config{};
  std::vector<double> bers;
  std::string json;
};

Options ParseArgs(int argc, char** argv) {
  namespace off = railproof::offline;
  Options o;
  ResidualConfig& config = o.config;
  config.code = {static_cast<unsigned>(tg::rs_n), static_cast<unsigned>(tg::rs_k), DefaultM()};
  config.blocks = DefaultBlocks();
  config.bit_rate_bps = static_cast<double>(tg::radio_bit_rate_bps);
  config.target_per_hour = static_cast<double>(tg::residual_target_per_h);
  config.crc_pass = std::ldexp(1.0L, -16);
  double tag_pass = std::ldexp(1.0, -128);
  off::Cli cli("residual_error", Description() + "\nPrints a table.", "0 done");
  cli.Add("--ber", o.bers, "bit error probability in [0, 1]; repeatable")->check(off::InRange(0.0, 1.0));
  cli.Add("--bit-rate", config.bit_rate_bps, "channel bit rate (bit/s)")->check(off::Above(0.0));
  cli.Add("--n", config.code.n, "code length (symbols)");
  cli.Add("--k", config.code.k, "code dimension (symbols)");
  cli.Add("--m", config.code.m, "symbol bits, 2..8");
  cli.Add("--blocks", config.blocks, "RS blocks per frame (default: the longest frame)")->check(off::InRange(1, 1e9));
  cli.Add("--target", config.target_per_hour, "residual target per hour")->check(off::Above(0.0));
  cli.Add("--tag-pass", tag_pass, "probability that a wrong frame passes the tag")->check(off::InRange(0.0, 1.0));
  cli.Add("--json", o.json, "also write the results as JSON");
  cli.ParseOrExit(argc, argv);
  try {
    railproof::tg::analysis::ValidateCode(config.code);
  } catch (const std::invalid_argument& e) {
    cli.Fail(std::string("--n, --k, --m: ") + e.what());
  }
  config.tag_pass = static_cast<long double>(tag_pass);
  if (o.bers.empty()) {  // the two bit error rates D5 reports (spec/parameters)
    o.bers.push_back(static_cast<double>(tg::design_ber));
    o.bers.push_back(static_cast<double>(tg::comparison_ber));
  }
  return o;
}

int Main(int argc, char** argv) {
  const Options o = ParseArgs(argc, argv);
  railproof::offline::OutputFiles out;
  if (!o.json.empty()) {
    out.Reserve(o.json);
  }
  std::vector<ResidualResult> results;
  for (const double b : o.bers) {
    results.push_back(railproof::tg::analysis::ComputeResidual(o.config, b));
  }
  std::cout << railproof::tg::analysis::ResidualReportTable(o.config, results);
  if (!o.json.empty()) {
    out.Write(o.json, railproof::tg::analysis::ResidualReportJson(o.config, results));
  }
  out.Commit();
  if (!o.json.empty()) {
    std::cout << "wrote " << o.json << "\n";
  }
  return 0;
}

}  // namespace

// @implements REQ-TG-019
int main(int argc, char** argv) {
  return railproof::offline::RunTool("residual_error", [&] { return Main(argc, argv); });
}
