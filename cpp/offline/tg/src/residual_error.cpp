// Residual error of the link coding (REQ-TG-019). Derivation: see the header comment.
#include "railproof/tg/analysis/residual_error.hpp"

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>

namespace railproof::tg::analysis {

namespace {

long double Q(const CodeSpec& code) { return std::ldexp(1.0L, static_cast<int>(code.m)); }

unsigned Radius(const CodeSpec& code) { return (code.n - code.k) / 2U; }

unsigned MinDistance(const CodeSpec& code) { return code.n - code.k + 1U; }

// Probability of one specific error vector of weight h: x^h y^(n-h), x = p_s/(q-1), y = 1-p_s.
long double VectorProbability(long double x, long double y, unsigned h, unsigned n) {
  return std::pow(x, static_cast<long double>(h)) * std::pow(y, static_cast<long double>(n - h));
}

std::string Num(long double v) {
  if (!std::isfinite(v)) {
    return "null";
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10Le", v);
  return buf;
}

std::string Bool(bool b) { return b ? "true" : "false"; }

}  // namespace

// @implements REQ-TG-019
void ValidateCode(const CodeSpec& code) {
  if (code.m < 2U || code.m > 8U) {
    throw std::invalid_argument("m must be in 2..8 (GF(2^m) symbols of at most one byte)");
  }
  const unsigned q = 1U << code.m;
  if (code.n < 2U || code.n > q - 1U) {
    throw std::invalid_argument("n must be in 2..2^m-1 (" + std::to_string(q - 1U) + ")");
  }
  if (code.k < 1U || code.k >= code.n) {
    throw std::invalid_argument("k must satisfy 1 <= k < n");
  }
}

// @implements REQ-TG-019
long double Binomial(unsigned n, unsigned r) {
  if (r > n) {
    return 0.0L;
  }
  if (r > n - r) {
    r = n - r;
  }
  long double c = 1.0L;
  for (unsigned i = 0; i < r; ++i) {
    c = c * static_cast<long double>(n - i) / static_cast<long double>(i + 1U);
  }
  // Every intermediate value C(n,i+1)(i+1) is an integer, exact while below 2^64; round
  // away representation noise there, keep the (relative-accurate) value above.
  return c < 0x1p63L ? std::round(c) : c;
}

namespace {

// Pascal's triangle up to n (exact below 2^64, relative error ~n * 1e-19 above).
class BinomialTable {
 public:
  explicit BinomialTable(unsigned n) : n_(n), c_((n + 1U) * (n + 1U), 0.0L) {
    for (unsigned i = 0; i <= n; ++i) {
      At(i, 0) = 1.0L;
      for (unsigned r = 1; r <= i; ++r) {
        At(i, r) = At(i - 1U, r - 1U) + (r < i ? At(i - 1U, r) : 0.0L);
      }
    }
  }
  long double operator()(unsigned i, unsigned r) const {
    return (r > i) ? 0.0L : c_[static_cast<std::size_t>(i) * (n_ + 1U) + r];
  }

 private:
  long double& At(unsigned i, unsigned r) { return c_[static_cast<std::size_t>(i) * (n_ + 1U) + r]; }
  unsigned n_;
  std::vector<long double> c_;
};

std::vector<long double> Powers(long double base, unsigned max_exp) {
  std::vector<long double> p(max_exp + 1U, 1.0L);
  for (unsigned e = 1; e <= max_exp; ++e) {
    p[e] = p[e - 1U] * base;
  }
  return p;
}

std::vector<long double> WeightDistribution(const CodeSpec& code, const BinomialTable& c) {
  const unsigned d = MinDistance(code);
  const auto qpow = Powers(Q(code), code.n);  // exact: powers of two
  std::vector<long double> a(code.n + 1U, 0.0L);
  a[0] = 1.0L;
  for (unsigned w = d; w <= code.n; ++w) {
    // Sum positive and negative terms separately, then subtract once.
    long double pos = 0.0L;
    long double neg = 0.0L;
    for (unsigned j = 0; j <= w - d; ++j) {
      const long double term = c(w, j) * (qpow[w - d + 1U - j] - 1.0L);
      ((j % 2U == 0U) ? pos : neg) += term;
    }
    a[w] = c(code.n, w) * (pos - neg);
  }
  return a;
}

// N(w,h) of the header, section 5, directly from its definition.
long double Sphere(const CodeSpec& code, const BinomialTable& c, unsigned w, unsigned h, unsigned t) {
  const long double q = Q(code);
  long double total = 0.0L;
  const unsigned i_min = (w > t) ? w - t : 0U;
  for (unsigned i = i_min; i <= w && i <= h; ++i) {
    const unsigned dist_support = w - i;  // j + l
    for (unsigned u = 0; u <= code.n - w && dist_support + u <= t && i + u <= h; ++u) {
      const unsigned j = h - i - u;
      if (j > w - i) {
        continue;
      }
      total += c(w, i) * c(w - i, j) * std::pow(q - 2.0L, static_cast<long double>(j)) *
               c(code.n - w, u) * std::pow(q - 1.0L, static_cast<long double>(u));
    }
  }
  return total;
}

// mis[h] = sum_w A_w N(w,h), accumulated over the (w, i, j, u) of section 5 directly, so
// only the non-zero terms are visited (h lies in [w - t, w + t]).
std::vector<long double> MiscorrectCounts(const CodeSpec& code, const BinomialTable& c,
                                          const std::vector<long double>& a) {
  const unsigned n = code.n;
  const unsigned t = Radius(code);
  const auto p2 = Powers(Q(code) - 2.0L, n);
  const auto p1 = Powers(Q(code) - 1.0L, n);
  std::vector<long double> mis(n + 1U, 0.0L);
  for (unsigned w = MinDistance(code); w <= n; ++w) {
    for (unsigned i = w - t; i <= w; ++i) {
      const unsigned changed = w - i;  // j + l, each costs distance 1
      for (unsigned u = 0; u <= n - w && changed + u <= t; ++u) {
        const long double base = a[w] * c(w, i) * c(n - w, u) * p1[u];
        for (unsigned j = 0; j <= changed; ++j) {
          mis[i + j + u] += base * c(changed, j) * p2[j];
        }
      }
    }
  }
  return mis;
}

}  // namespace

// @implements REQ-TG-019
std::vector<long double> MdsWeightDistribution(const CodeSpec& code) {
  ValidateCode(code);
  return WeightDistribution(code, BinomialTable(code.n));
}

// @implements REQ-TG-019
long double SphereCount(const CodeSpec& code, unsigned w, unsigned h, unsigned t) {
  ValidateCode(code);
  if (w > code.n || h > code.n) {
    throw std::invalid_argument("weight exceeds n");
  }
  return Sphere(code, BinomialTable(code.n), w, h, t);
}

// @implements REQ-TG-019
std::vector<WeightClassCounts> CountsByErrorWeight(const CodeSpec& code) {
  ValidateCode(code);
  const BinomialTable c(code.n);
  const unsigned t = Radius(code);
  const auto mis = MiscorrectCounts(code, c, WeightDistribution(code, c));
  const auto p1 = Powers(Q(code) - 1.0L, code.n);
  std::vector<WeightClassCounts> out(code.n + 1U);
  for (unsigned h = 0; h <= code.n; ++h) {
    const long double all = c(code.n, h) * p1[h];
    out[h].correct = (h <= t) ? all : 0.0L;
    out[h].miscorrect = mis[h];
    out[h].detected = (h <= t) ? 0.0L : all - mis[h];
  }
  return out;
}

// @implements REQ-TG-019
long double SymbolErrorProbability(long double p_b, unsigned m) {
  if (!(p_b >= 0.0L && p_b <= 1.0L)) {
    throw std::invalid_argument("bit error probability must be in [0, 1]");
  }
  if (p_b == 1.0L) {
    return 1.0L;
  }
  return -std::expm1(static_cast<long double>(m) * std::log1p(-p_b));
}

// @implements REQ-TG-019
BlockOutcome BlockOutcomeForSymbolErrorProbability(const CodeSpec& code, long double p_s) {
  ValidateCode(code);
  if (!(p_s >= 0.0L && p_s <= 1.0L)) {
    throw std::invalid_argument("symbol error probability must be in [0, 1]");
  }
  const unsigned n = code.n;
  const long double x = p_s / (Q(code) - 1.0L);  // probability of one specific wrong value
  const long double y = 1.0L - p_s;
  const auto counts = CountsByErrorWeight(code);
  BlockOutcome out{};
  out.p_symbol = p_s;
  for (unsigned h = 0; h <= n; ++h) {
    const long double pv = VectorProbability(x, y, h, n);
    out.p_correct += counts[h].correct * pv;
    out.p_miscorrect += counts[h].miscorrect * pv;
    out.p_uncorrectable += counts[h].detected * pv;
  }
  return out;
}

// @implements REQ-TG-019
ResidualResult ComputeResidual(const ResidualConfig& config, double ber) {
  ValidateCode(config.code);
  if (config.blocks < 1U) {
    throw std::invalid_argument("blocks must be >= 1");
  }
  if (!(config.bit_rate_bps > 0.0) || !std::isfinite(config.bit_rate_bps)) {
    throw std::invalid_argument("bit rate must be a positive number");
  }
  if (!(config.target_per_hour > 0.0) || !std::isfinite(config.target_per_hour)) {
    throw std::invalid_argument("target must be a positive number");
  }
  if (!(config.crc_pass >= 0.0L && config.crc_pass <= 1.0L) ||
      !(config.tag_pass >= 0.0L && config.tag_pass <= 1.0L)) {
    throw std::invalid_argument("pass probabilities must be in [0, 1]");
  }
  if (!(ber >= 0.0 && ber <= 1.0)) {
    throw std::invalid_argument("ber must be in [0, 1]");
  }
  ResidualResult r{};
  r.ber = ber;
  r.block = BlockOutcomeForSymbolErrorProbability(
      config.code, SymbolErrorProbability(static_cast<long double>(ber), config.code.m));
  const unsigned b = config.blocks;
  for (unsigned j = 1; j <= b; ++j) {
    r.p_frame_rs_wrong += Binomial(b, j) * std::pow(r.block.p_miscorrect, static_cast<long double>(j)) *
                          std::pow(r.block.p_correct, static_cast<long double>(b - j));
  }
  r.p_frame_rs_rejected =
      -std::expm1(static_cast<long double>(b) * std::log1p(-r.block.p_uncorrectable));
  r.p_undetected_frame_crc = r.p_frame_rs_wrong * config.crc_pass;
  r.p_undetected_frame_crc_mac = r.p_undetected_frame_crc * config.tag_pass;
  const long double bits_per_frame =
      static_cast<long double>(b) * config.code.n * config.code.m;
  r.telegrams_per_hour = static_cast<long double>(config.bit_rate_bps) / bits_per_frame * 3600.0L;
  r.per_hour_crc = r.p_undetected_frame_crc * r.telegrams_per_hour;
  r.per_hour_crc_mac = r.p_undetected_frame_crc_mac * r.telegrams_per_hour;
  const auto target = static_cast<long double>(config.target_per_hour);
  r.meets_target_crc = r.per_hour_crc < target;
  r.meets_target_crc_mac = r.per_hour_crc_mac < target;
  return r;
}

// @implements REQ-TG-019
std::string ResidualReportJson(const ResidualConfig& config,
                               const std::vector<ResidualResult>& results) {
  ValidateCode(config.code);
  const CodeSpec& c = config.code;
  const auto a = MdsWeightDistribution(c);
  const unsigned bits_per_frame = config.blocks * c.n * c.m;
  std::ostringstream o;
  o << "{\n";
  o << "  \"tool\": \"residual_error\",\n";
  o << "  \"schema_version\": 1,\n";
  o << "  \"requirements\": [\"REQ-TG-019\", \"REQ-TG-010\"],\n";
  o << "  \"code\": {\"n\": " << c.n << ", \"k\": " << c.k << ", \"m\": " << c.m
    << ", \"q\": " << (1U << c.m) << ", \"d\": " << MinDistance(c) << ", \"t\": " << Radius(c)
    << ", \"A_d\": " << Num(a[MinDistance(c)]) << "},\n";
  o << "  \"blocks_per_frame\": " << config.blocks << ",\n";
  o << "  \"bits_per_frame\": " << bits_per_frame << ",\n";
  o << "  \"bit_rate_bps\": " << Num(static_cast<long double>(config.bit_rate_bps)) << ",\n";
  o << "  \"telegrams_per_hour\": "
    << Num(static_cast<long double>(config.bit_rate_bps) / bits_per_frame * 3600.0L) << ",\n";
  o << "  \"per_hour_definition\": \"P_undetected per telegram x telegrams per hour, where "
       "telegrams per hour = bit_rate_bps / bits_per_frame x 3600 (a channel carrying "
       "frames back-to-back at the given bit rate)\",\n";
  o << "  \"target_per_hour\": " << Num(static_cast<long double>(config.target_per_hour))
    << ",\n";
  o << "  \"crc_pass_probability\": " << Num(config.crc_pass) << ",\n";
  o << "  \"tag_pass_probability\": " << Num(config.tag_pass) << ",\n";
  o << "  \"assumptions\": [\n"
       "    \"bit errors independent with probability ber; symbol errors independent with "
       "p_s = 1-(1-ber)^m, a wrong symbol uniformly one of the q-1 other values\",\n"
       "    \"each RS block decoded independently by a strict bounded-distance decoder of "
       "radius t\",\n"
       "    \"a wrong frame passes the CRC-16 with probability 2^-16\",\n"
       "    \"a wrong frame passes the 128-bit authentication tag with probability "
       "tag_pass_probability (default 2^-128, ideal tag; the proven Poly1305 bound is "
       "8*ceil(L/16)/2^106)\"\n"
       "  ],\n";
  o << "  \"results\": [";
  for (std::size_t i = 0; i < results.size(); ++i) {
    const ResidualResult& r = results[i];
    o << (i == 0 ? "\n" : ",\n");
    o << "    {\"ber\": " << Num(static_cast<long double>(r.ber))
      << ", \"p_s\": " << Num(r.block.p_symbol)
      << ", \"p_correct_block\": " << Num(r.block.p_correct)
      << ", \"p_miscorrect_block\": " << Num(r.block.p_miscorrect)
      << ", \"p_uncorrectable_block\": " << Num(r.block.p_uncorrectable)
      << ", \"p_frame_rs_wrong\": " << Num(r.p_frame_rs_wrong)
      << ", \"p_frame_rs_rejected\": " << Num(r.p_frame_rs_rejected)
      << ", \"p_undetected_frame_crc\": " << Num(r.p_undetected_frame_crc)
      << ", \"p_undetected_frame_crc_mac\": " << Num(r.p_undetected_frame_crc_mac)
      << ", \"per_hour_crc\": " << Num(r.per_hour_crc)
      << ", \"per_hour_crc_mac\": " << Num(r.per_hour_crc_mac)
      << ", \"target\": " << Num(static_cast<long double>(config.target_per_hour))
      << ", \"meets_target_crc\": " << Bool(r.meets_target_crc)
      << ", \"meets_target_crc_mac\": " << Bool(r.meets_target_crc_mac)
      // REQ-TG-019 is judged conservatively on RS + CRC alone (as D5 does), without
      // credit for the authentication tag.
      << ", \"meets_target\": " << Bool(r.meets_target_crc) << "}";
  }
  o << (results.empty() ? "]\n" : "\n  ]\n");
  o << "}\n";
  return o.str();
}

// @implements REQ-TG-019
std::string ResidualReportTable(const ResidualConfig& config,
                                const std::vector<ResidualResult>& results) {
  ValidateCode(config.code);
  const CodeSpec& c = config.code;
  const unsigned bits_per_frame = config.blocks * c.n * c.m;
  std::ostringstream o;
  char line[512];
  std::snprintf(line, sizeof line,
                "Residual error of RS(%u,%u) over GF(2^%u) (d = %u, t = %u), %u block(s) per "
                "frame = %u bits\n",
                c.n, c.k, c.m, MinDistance(c), Radius(c), config.blocks, bits_per_frame);
  o << line;
  std::snprintf(line, sizeof line,
                "bit rate %.0f bit/s -> %.1f telegrams/h (frames back-to-back); target %.1e /h\n",
                config.bit_rate_bps,
                config.bit_rate_bps / static_cast<double>(bits_per_frame) * 3600.0,
                config.target_per_hour);
  o << line;
  std::snprintf(line, sizeof line,
                "assumed pass probabilities: CRC-16 %.3Le, authentication tag %.3Le\n\n",
                config.crc_pass, config.tag_pass);
  o << line;
  std::snprintf(line, sizeof line, "%-10s %-10s %-10s %-10s %-10s %-10s %-10s %-10s %-5s %-5s\n",
                "ber", "p_s", "P_mis/blk", "P_det/blk", "P_wrong/fr", "CRC /tg", "CRC /h",
                "+MAC /h", "CRC", "+MAC");
  o << line;
  for (const ResidualResult& r : results) {
    std::snprintf(line, sizeof line,
                  "%-10.3e %-10.3Le %-10.3Le %-10.3Le %-10.3Le %-10.3Le %-10.3Le %-10.3Le %-5s %-5s\n",
                  r.ber, r.block.p_symbol, r.block.p_miscorrect, r.block.p_uncorrectable,
                  r.p_frame_rs_wrong, r.p_undetected_frame_crc, r.per_hour_crc,
                  r.per_hour_crc_mac, r.meets_target_crc ? "ok" : "FAIL",
                  r.meets_target_crc_mac ? "ok" : "FAIL");
    o << line;
  }
  o << "\nCRC /h and +MAC /h are rates of undetected erroneous telegrams per hour; ok means "
       "below the target.\n";
  return o.str();
}

}  // namespace railproof::tg::analysis
