// Unit tests of the Reed-Solomon link code (REQ-TG-010; D5 §6.3; ASM-008).
// Reference values are computed independently: a table-free shift-and-add GF(2^8)
// multiplication and a plain polynomial long division live in this file, and the literal
// known-answer parities were produced by a separate Python implementation
// (generator roots alpha^1..alpha^16, field polynomial 0x11D).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <random>
#include <span>
#include <string_view>
#include <vector>

#include "railproof/generated/tg_params.hpp"
#include "railproof/tg/reed_solomon.hpp"

namespace {

using namespace railproof::tg;  // NOLINT(google-build-using-namespace)
using Bytes = std::vector<std::uint8_t>;

namespace tg = railproof::params::tg;

constexpr RsParams kParams6650{8, static_cast<unsigned>(tg::gf_primitive_poly),
                               static_cast<unsigned>(tg::rs_n), static_cast<unsigned>(tg::rs_k)};

// ---- independent reference: bitwise GF(2^m) and long division --------------------------
unsigned RefMul(unsigned a, unsigned b, unsigned m, unsigned poly) {
  unsigned r = 0;
  const unsigned top = 1U << m;
  while (b != 0U) {
    if ((b & 1U) != 0U) {
      r ^= a;
    }
    a <<= 1U;
    if ((a & top) != 0U) {
      a ^= poly;
    }
    b >>= 1U;
  }
  return r;
}

// Generator coefficients, highest degree first: prod_{j=1}^{nroots} (x + alpha^j).
std::vector<unsigned> RefGenerator(unsigned nroots, unsigned m, unsigned poly) {
  std::vector<unsigned> g{1};
  unsigned root = 1;
  for (unsigned j = 1; j <= nroots; ++j) {
    root = RefMul(root, 2, m, poly);
    std::vector<unsigned> next(g.size() + 1, 0);
    for (std::size_t i = 0; i < g.size(); ++i) {
      next[i] ^= g[i];
      next[i + 1] ^= RefMul(g[i], root, m, poly);
    }
    g = next;
  }
  return g;
}

// Remainder of msg(x) * x^nroots divided by g(x) (schoolbook long division).
Bytes RefParity(const Bytes& msg, unsigned nroots, unsigned m, unsigned poly) {
  const auto g = RefGenerator(nroots, m, poly);
  std::vector<unsigned> rem(msg.begin(), msg.end());
  rem.resize(msg.size() + nroots, 0);
  for (std::size_t i = 0; i < msg.size(); ++i) {
    const unsigned coef = rem[i];
    if (coef != 0U) {
      for (std::size_t j = 1; j < g.size(); ++j) {
        rem[i + j] ^= RefMul(g[j], coef, m, poly);
      }
    }
  }
  Bytes parity;
  for (std::size_t i = msg.size(); i < rem.size(); ++i) {
    parity.push_back(static_cast<std::uint8_t>(rem[i]));
  }
  return parity;
}

// ---- helpers ---------------------------------------------------------------------------
Bytes RandomMessage(std::mt19937& rng, unsigned k, unsigned q) {
  std::uniform_int_distribution<unsigned> sym(0, q - 1U);
  Bytes msg(k);
  for (auto& s : msg) {
    s = static_cast<std::uint8_t>(sym(rng));
  }
  return msg;
}

Bytes EncodeOrDie(const ReedSolomon& rs, const Bytes& msg) {
  Bytes cw(rs.n(), 0);
  EXPECT_EQ(rs.Encode(msg, cw), RsStatus::kOk);
  return cw;
}

// Adds `count` non-zero errors at distinct random positions drawn from [lo, hi).
void InjectErrors(std::mt19937& rng, Bytes& word, unsigned count, unsigned q, unsigned lo,
                  unsigned hi) {
  std::vector<unsigned> positions(hi - lo);
  for (unsigned i = 0; i < positions.size(); ++i) {
    positions[i] = lo + i;
  }
  std::shuffle(positions.begin(), positions.end(), rng);
  std::uniform_int_distribution<unsigned> val(1, q - 1U);
  for (unsigned i = 0; i < count; ++i) {
    word[positions[i]] = static_cast<std::uint8_t>(word[positions[i]] ^ val(rng));
  }
}

unsigned Distance(const Bytes& a, const Bytes& b) {
  unsigned d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    d += (a[i] != b[i]) ? 1U : 0U;
  }
  return d;
}

// ---- known answers ---------------------------------------------------------------------

// @verifies REQ-TG-010
TEST(ReedSolomon, Rs6650Parameters) {
  const ReedSolomon& rs = Rs6650();
  ASSERT_TRUE(rs.valid());
  EXPECT_EQ(rs.n(), 66U);
  EXPECT_EQ(rs.k(), 50U);
  EXPECT_EQ(rs.t(), 8U);
  EXPECT_EQ(rs.t(), static_cast<unsigned>(tg::rs_t));
  EXPECT_EQ(rs.field().m(), 8U);
  EXPECT_EQ(rs.field().primitive_poly(), 0x11DU);
  EXPECT_EQ(&Rs6650(), &rs);  // one instance
}

// g(x) = prod_{j=1}^{16} (x + alpha^j) over GF(2^8)/0x11D, highest degree first.
// @verifies REQ-TG-010
TEST(ReedSolomon, Rs6650GeneratorKnownAnswer) {
  const std::array<std::uint8_t, 17> expected = {0x01, 0x76, 0x34, 0x67, 0x1F, 0x68,
                                                 0x7E, 0xBB, 0xE8, 0x11, 0x38, 0xB7,
                                                 0x31, 0x64, 0x51, 0x2C, 0x4F};
  const ReedSolomon& rs = Rs6650();
  for (unsigned i = 0; i <= 16U; ++i) {
    EXPECT_EQ(rs.generator_coefficient(16U - i), expected[i]) << "x^" << (16U - i);
  }
  const auto ref = RefGenerator(16, 8, 0x11D);
  for (unsigned i = 0; i <= 16U; ++i) {
    EXPECT_EQ(ref[i], expected[i]);
  }
}

// @verifies REQ-TG-010
TEST(ReedSolomon, Rs6650ParityKnownAnswers) {
  const ReedSolomon& rs = Rs6650();
  {
    constexpr std::string_view text = "railproof RS(66,50) known-answer message, 50 bytes";
    static_assert(text.size() == 50);
    const Bytes msg(text.begin(), text.end());
    const Bytes expected = {0x33, 0x7C, 0xE3, 0xF6, 0xA4, 0x81, 0x40, 0x95,
                            0x67, 0xBE, 0x5B, 0xAE, 0x2F, 0x8E, 0x07, 0x83};
    const Bytes cw = EncodeOrDie(rs, msg);
    EXPECT_TRUE(std::equal(msg.begin(), msg.end(), cw.begin()));
    EXPECT_EQ(Bytes(cw.begin() + 50, cw.end()), expected);
    EXPECT_EQ(RefParity(msg, 16, 8, 0x11D), expected);
  }
  {
    Bytes msg(50);
    for (unsigned i = 0; i < 50U; ++i) {
      msg[i] = static_cast<std::uint8_t>((i * 37U + 11U) % 256U);
    }
    const Bytes expected = {0x80, 0x35, 0x12, 0xCA, 0xB3, 0xBA, 0xB8, 0x6D,
                            0x9E, 0x68, 0x20, 0xE4, 0x4F, 0xEE, 0x00, 0xD3};
    const Bytes cw = EncodeOrDie(rs, msg);
    EXPECT_EQ(Bytes(cw.begin() + 50, cw.end()), expected);
  }
}

// Encoder against the in-test long division for random messages of several codes, and
// every codeword evaluates to zero at the roots alpha^1..alpha^(n-k) (table-free check).
// @verifies REQ-TG-010
TEST(ReedSolomon, EncoderMatchesLongDivisionReference) {
  const RsParams codes[] = {kParams6650, {8, 0x11D, 255, 223}, {8, 0x11D, 20, 4},
                            {4, 0x13, 15, 11}, {4, 0x19, 12, 5}, {3, 0xB, 7, 3}};
  std::mt19937 rng(1234);
  for (const RsParams& p : codes) {
    const ReedSolomon rs(p);
    ASSERT_TRUE(rs.valid());
    for (int trial = 0; trial < 50; ++trial) {
      const Bytes msg = RandomMessage(rng, p.k, 1U << p.m);
      const Bytes cw = EncodeOrDie(rs, msg);
      ASSERT_EQ(Bytes(cw.begin() + p.k, cw.end()), RefParity(msg, p.n - p.k, p.m, p.primitive_poly));
      for (unsigned j = 1; j <= p.n - p.k; ++j) {
        unsigned root = 1;
        for (unsigned e = 0; e < j; ++e) {
          root = RefMul(root, 2, p.m, p.primitive_poly);
        }
        unsigned acc = 0;
        for (const std::uint8_t s : cw) {
          acc = RefMul(acc, root, p.m, p.primitive_poly) ^ s;
        }
        ASSERT_EQ(acc, 0U) << "root alpha^" << j;
      }
      EXPECT_TRUE(rs.IsCodeword(cw));
    }
  }
}

// @verifies REQ-TG-010
TEST(ReedSolomon, EncodeInPlaceAliasing) {
  const ReedSolomon& rs = Rs6650();
  std::mt19937 rng(77);
  const Bytes msg = RandomMessage(rng, 50, 256);
  const Bytes expected = EncodeOrDie(rs, msg);
  Bytes buf(66, 0xAA);
  std::copy(msg.begin(), msg.end(), buf.begin());
  ASSERT_EQ(rs.Encode(std::span<const std::uint8_t>(buf).first(50), buf), RsStatus::kOk);
  EXPECT_EQ(buf, expected);
}

// ---- decoding within the radius --------------------------------------------------------

// 0..t random symbol errors at random positions always restore the codeword, with the
// exact number of corrections reported. Many seeded trials per error count.
// @verifies REQ-TG-010
TEST(ReedSolomon, Rs6650CorrectsUpToEightRandomErrors) {
  const ReedSolomon& rs = Rs6650();
  std::mt19937 rng(20240601);
  for (unsigned errors = 0; errors <= 8U; ++errors) {
    for (int trial = 0; trial < 1500; ++trial) {
      const Bytes cw = EncodeOrDie(rs, RandomMessage(rng, 50, 256));
      Bytes rx = cw;
      InjectErrors(rng, rx, errors, 256, 0, 66);
      const RsDecodeResult r = rs.Decode(rx);
      ASSERT_EQ(r.status, errors == 0U ? RsStatus::kOk : RsStatus::kCorrected)
          << errors << " errors, trial " << trial;
      ASSERT_EQ(r.corrected_symbols, errors);
      ASSERT_EQ(rx, cw);
    }
  }
}

// Every single-symbol error (all positions x all 255 error values) is corrected.
// @verifies REQ-TG-010
TEST(ReedSolomon, Rs6650CorrectsEverySingleSymbolError) {
  const ReedSolomon& rs = Rs6650();
  std::mt19937 rng(5);
  const Bytes cw = EncodeOrDie(rs, RandomMessage(rng, 50, 256));
  for (unsigned pos = 0; pos < 66U; ++pos) {
    for (unsigned v = 1; v < 256U; ++v) {
      Bytes rx = cw;
      rx[pos] = static_cast<std::uint8_t>(rx[pos] ^ v);
      const RsDecodeResult r = rs.Decode(rx);
      ASSERT_EQ(r.status, RsStatus::kCorrected) << "pos " << pos << " value " << v;
      ASSERT_EQ(r.corrected_symbols, 1U);
      ASSERT_EQ(rx, cw);
    }
  }
}

// Errors confined to the parity symbols, or to the data symbols, or one burst of t
// consecutive symbols anywhere.
// @verifies REQ-TG-010
TEST(ReedSolomon, Rs6650ParityOnlyDataOnlyAndBurstErrors) {
  const ReedSolomon& rs = Rs6650();
  std::mt19937 rng(99);
  for (int trial = 0; trial < 200; ++trial) {
    const Bytes cw = EncodeOrDie(rs, RandomMessage(rng, 50, 256));
    for (unsigned errors = 1; errors <= 8U; ++errors) {
      Bytes parity_hit = cw;
      InjectErrors(rng, parity_hit, errors, 256, 50, 66);
      EXPECT_TRUE(std::equal(cw.begin(), cw.begin() + 50, parity_hit.begin()));
      ASSERT_EQ(rs.Decode(parity_hit).status, RsStatus::kCorrected);
      ASSERT_EQ(parity_hit, cw);

      Bytes data_hit = cw;
      InjectErrors(rng, data_hit, errors, 256, 0, 50);
      ASSERT_EQ(rs.Decode(data_hit).status, RsStatus::kCorrected);
      ASSERT_EQ(data_hit, cw);
    }
    const unsigned start = static_cast<unsigned>(trial) % (66U - 8U + 1U);
    Bytes burst = cw;
    std::uniform_int_distribution<unsigned> val(1, 255);
    for (unsigned i = start; i < start + 8U; ++i) {
      burst[i] = static_cast<std::uint8_t>(burst[i] ^ val(rng));
    }
    const RsDecodeResult r = rs.Decode(burst);
    ASSERT_EQ(r.status, RsStatus::kCorrected);
    ASSERT_EQ(r.corrected_symbols, 8U);
    ASSERT_EQ(burst, cw);
  }
}

// The parity symbols of all-zero data with one error are corrected too (the all-zero
// codeword is a codeword like any other).
// @verifies REQ-TG-010
TEST(ReedSolomon, ZeroCodeword) {
  const ReedSolomon& rs = Rs6650();
  Bytes zero(66, 0);
  EXPECT_EQ(rs.Decode(zero).status, RsStatus::kOk);
  Bytes rx = zero;
  rx[65] = 1;
  rx[0] = 0xFF;
  const RsDecodeResult r = rs.Decode(rx);
  EXPECT_EQ(r.status, RsStatus::kCorrected);
  EXPECT_EQ(r.corrected_symbols, 2U);
  EXPECT_EQ(rx, zero);
}

// ---- beyond the radius -----------------------------------------------------------------

struct BeyondCounts {
  unsigned uncorrectable = 0;
  unsigned miscorrected = 0;
};

// Decodes words with more than t errors; every outcome must be either kUncorrectable with
// the buffer unchanged, or a mis-correction to ANOTHER codeword at distance <= t from the
// received word (bounded-distance decoding cannot do better). Never a non-codeword.
BeyondCounts RunBeyondRadius(const ReedSolomon& rs, std::uint32_t seed, unsigned min_errors,
                             unsigned max_errors, int trials) {
  std::mt19937 rng(seed);
  const unsigned q = rs.field().size();
  std::uniform_int_distribution<unsigned> count(min_errors, max_errors);
  BeyondCounts counts;
  for (int trial = 0; trial < trials; ++trial) {
    const Bytes cw = EncodeOrDie(rs, RandomMessage(rng, rs.k(), q));
    Bytes rx = cw;
    InjectErrors(rng, rx, count(rng), q, 0, rs.n());
    const Bytes received = rx;
    const RsDecodeResult r = rs.Decode(rx);
    if (r.status == RsStatus::kUncorrectable) {
      EXPECT_EQ(rx, received) << "buffer modified on rejection, trial " << trial;
      EXPECT_EQ(r.corrected_symbols, 0U);
      ++counts.uncorrectable;
    } else {
      EXPECT_TRUE(r.status == RsStatus::kCorrected || r.status == RsStatus::kOk);
      EXPECT_TRUE(rs.IsCodeword(rx)) << "decoder output is not a codeword";
      EXPECT_NE(rx, cw);
      EXPECT_LE(Distance(rx, received), rs.t());
      EXPECT_EQ(Distance(rx, received), r.corrected_symbols);
      ++counts.miscorrected;
    }
  }
  return counts;
}

// @verifies REQ-TG-010
TEST(ReedSolomon, Rs6650BeyondRadiusIsRejectedOrMiscorrectedNeverCorrupted) {
  const int trials = 5000;
  const BeyondCounts c = RunBeyondRadius(Rs6650(), 4242, 9, 40, trials);
  EXPECT_EQ(c.uncorrectable + c.miscorrected, static_cast<unsigned>(trials));
  // For RS(66,50) a random word far from the sent one lies within radius 8 of some
  // codeword with probability about sum_{h<=8} C(66,h) 255^h / 256^16 < 1e-9.
  EXPECT_EQ(c.miscorrected, 0U);
  RecordProperty("uncorrectable", static_cast<int>(c.uncorrectable));
  RecordProperty("miscorrected", static_cast<int>(c.miscorrected));
}

// A short code where mis-correction is frequent exercises the acceptance path beyond the
// radius: RS(15,11) over GF(16), t = 2.
// @verifies REQ-TG-010
TEST(ReedSolomon, ShortCodeBeyondRadiusCountsBothOutcomes) {
  const ReedSolomon rs(RsParams{4, 0x13, 15, 11});
  ASSERT_TRUE(rs.valid());
  const int trials = 20000;
  const BeyondCounts c = RunBeyondRadius(rs, 31337, 3, 15, trials);
  EXPECT_EQ(c.uncorrectable + c.miscorrected, static_cast<unsigned>(trials));
  EXPECT_GT(c.miscorrected, 0U);
  EXPECT_GT(c.uncorrectable, 0U);
  RecordProperty("uncorrectable", static_cast<int>(c.uncorrectable));
  RecordProperty("miscorrected", static_cast<int>(c.miscorrected));
}

// A word at distance t+1 from the sent codeword but at distance t from a minimum-weight
// neighbour must be decoded to that neighbour: the decoder is a bounded-distance decoder,
// not a detector, and the analysis (REQ-TG-019) counts exactly these events.
// @verifies REQ-TG-010
TEST(ReedSolomon, Rs6650DecodesToNearestNeighbourAtRadius) {
  const ReedSolomon& rs = Rs6650();
  Bytes msg(50, 0);
  msg[49] = 0x5A;
  const Bytes neighbour = EncodeOrDie(rs, msg);  // weight exactly d = 17 (MDS)
  unsigned weight = 0;
  for (const auto s : neighbour) {
    weight += (s != 0U) ? 1U : 0U;
  }
  ASSERT_EQ(weight, 17U);
  // Received word: 9 of the neighbour's non-zero symbols, sent codeword all zeros.
  Bytes rx(66, 0);
  unsigned taken = 0;
  for (unsigned i = 0; i < 66U && taken < 9U; ++i) {
    if (neighbour[i] != 0U) {
      rx[i] = neighbour[i];
      ++taken;
    }
  }
  const RsDecodeResult r = rs.Decode(rx);
  EXPECT_EQ(r.status, RsStatus::kCorrected);
  EXPECT_EQ(r.corrected_symbols, 8U);
  EXPECT_EQ(rx, neighbour);
}

// Exhaustive bounded-distance check of a tiny code: RS(7,3) over GF(8), t = 2. For every
// one of the 8^7 received words the decoder must return the unique codeword within
// distance 2 if there is one, and kUncorrectable (buffer unchanged) otherwise.
// @verifies REQ-TG-010
TEST(ReedSolomon, TinyCodeExhaustiveBoundedDistance) {
  const ReedSolomon rs(RsParams{3, 0xB, 7, 3});
  ASSERT_TRUE(rs.valid());
  constexpr unsigned kWords = 1U << 21U;  // 8^7
  auto index = [](const Bytes& w) {
    unsigned v = 0;
    for (const auto s : w) {
      v = (v << 3U) | s;
    }
    return v;
  };
  // expected[word] = index of its codeword + 1 within distance t, 0 if none.
  std::vector<std::uint16_t> expected(kWords, 0);
  std::vector<Bytes> codewords;
  for (unsigned m = 0; m < 512U; ++m) {
    const Bytes msg = {static_cast<std::uint8_t>(m >> 6U), static_cast<std::uint8_t>((m >> 3U) & 7U),
                       static_cast<std::uint8_t>(m & 7U)};
    codewords.push_back(EncodeOrDie(rs, msg));
  }
  for (std::size_t c = 0; c < codewords.size(); ++c) {
    const Bytes& cw = codewords[c];
    // All error patterns of weight <= 2.
    for (unsigned p1 = 0; p1 <= 7U; ++p1) {
      for (unsigned v1 = (p1 == 7U ? 0U : 1U); v1 < (p1 == 7U ? 1U : 8U); ++v1) {
        for (unsigned p2 = (p1 == 7U ? 7U : p1 + 1U); p2 <= 7U; ++p2) {
          for (unsigned v2 = (p2 == 7U ? 0U : 1U); v2 < (p2 == 7U ? 1U : 8U); ++v2) {
            Bytes w = cw;
            if (p1 < 7U) {
              w[p1] = static_cast<std::uint8_t>(w[p1] ^ v1);
            }
            if (p2 < 7U) {
              w[p2] = static_cast<std::uint8_t>(w[p2] ^ v2);
            }
            const unsigned idx = index(w);
            ASSERT_TRUE(expected[idx] == 0U || expected[idx] == c + 1U) << "spheres overlap";
            expected[idx] = static_cast<std::uint16_t>(c + 1U);
          }
        }
      }
    }
  }
  unsigned corrected = 0;
  unsigned rejected = 0;
  unsigned wrong = 0;  // any outcome other than the expected one (reported once)
  std::array<std::uint8_t, 7> w{};
  for (unsigned word = 0; word < kWords; ++word) {
    for (unsigned i = 0; i < 7U; ++i) {
      w[i] = static_cast<std::uint8_t>((word >> (3U * (6U - i))) & 7U);
    }
    const std::array<std::uint8_t, 7> received = w;
    const RsDecodeResult r = rs.Decode(w);
    if (expected[word] == 0U) {
      const bool ok = r.status == RsStatus::kUncorrectable && w == received;
      wrong += ok ? 0U : 1U;
      rejected += ok ? 1U : 0U;
    } else {
      const Bytes& cw = codewords[expected[word] - 1U];
      unsigned dist = 0;
      for (unsigned i = 0; i < 7U; ++i) {
        dist += (w[i] != received[i]) ? 1U : 0U;
      }
      const bool ok = r.status != RsStatus::kUncorrectable &&
                      std::equal(w.begin(), w.end(), cw.begin()) && r.corrected_symbols == dist;
      wrong += ok ? 0U : 1U;
      corrected += ok ? 1U : 0U;
    }
  }
  EXPECT_EQ(wrong, 0U);
  // 512 spheres of 1 + 7*7 + 21*49 = 1079 words each.
  EXPECT_EQ(corrected, 512U * 1079U);
  EXPECT_EQ(rejected, kWords - 512U * 1079U);
}

// Other shapes: the full-capacity RS(255,223) (n-k = kMaxParity), an odd number of parity
// symbols (t = floor((n-k)/2)), the smallest field GF(4), and a shortened GF(16) code.
// @verifies REQ-TG-010
TEST(ReedSolomon, OtherCodesCorrectUpToT) {
  const RsParams codes[] = {{8, 0x11D, 255, 223}, {4, 0x13, 15, 10}, {2, 0x7, 3, 1},
                            {4, 0x19, 12, 5}, {8, 0x11D, 66, 49}};
  std::mt19937 rng(8080);
  for (const RsParams& p : codes) {
    const ReedSolomon rs(p);
    ASSERT_TRUE(rs.valid());
    ASSERT_EQ(rs.t(), (p.n - p.k) / 2U);
    const unsigned q = 1U << p.m;
    const int trials = p.n > 100U ? 40 : 300;
    for (unsigned errors = 0; errors <= rs.t(); ++errors) {
      for (int trial = 0; trial < trials; ++trial) {
        const Bytes cw = EncodeOrDie(rs, RandomMessage(rng, p.k, q));
        Bytes rx = cw;
        InjectErrors(rng, rx, errors, q, 0, p.n);
        const RsDecodeResult r = rs.Decode(rx);
        ASSERT_EQ(r.corrected_symbols, errors) << "n=" << p.n << " k=" << p.k;
        ASSERT_EQ(rx, cw) << "n=" << p.n << " k=" << p.k;
      }
    }
  }
}

// ---- input validation ------------------------------------------------------------------

// @verifies REQ-TG-010
TEST(ReedSolomon, BadLengthIsRejectedWithoutTouchingBuffers) {
  const ReedSolomon& rs = Rs6650();
  for (const std::size_t len : {0U, 1U, 50U, 65U, 67U, 255U}) {
    Bytes buf(len, 0x33);
    const RsDecodeResult r = rs.Decode(buf);
    EXPECT_EQ(r.status, RsStatus::kBadLength) << len;
    EXPECT_EQ(r.corrected_symbols, 0U);
    EXPECT_EQ(buf, Bytes(len, 0x33));
  }
  Bytes cw(66, 0x44);
  EXPECT_EQ(rs.Encode(Bytes(49, 1), cw), RsStatus::kBadLength);
  EXPECT_EQ(rs.Encode(Bytes(51, 1), cw), RsStatus::kBadLength);
  EXPECT_EQ(cw, Bytes(66, 0x44));
  Bytes short_cw(65, 0x44);
  EXPECT_EQ(rs.Encode(Bytes(50, 1), short_cw), RsStatus::kBadLength);
  EXPECT_EQ(short_cw, Bytes(65, 0x44));
  EXPECT_FALSE(rs.IsCodeword(Bytes(65, 0)));
}

// For m < 8 a byte may hold a value outside GF(2^m): such a word is not over the code's
// alphabet and is uncorrectable; the buffer is left unchanged. Encoding rejects it too.
// @verifies REQ-TG-010
TEST(ReedSolomon, SymbolsOutsideTheFieldAreRejected) {
  const ReedSolomon rs(RsParams{4, 0x13, 15, 11});
  ASSERT_TRUE(rs.valid());
  std::mt19937 rng(16);
  const Bytes cw = EncodeOrDie(rs, RandomMessage(rng, 11, 16));
  for (const unsigned bad : {0x10U, 0x80U, 0xFFU}) {
    for (unsigned pos = 0; pos < 15U; ++pos) {
      Bytes rx = cw;
      rx[pos] = static_cast<std::uint8_t>(bad);
      const Bytes received = rx;
      const RsDecodeResult r = rs.Decode(rx);
      EXPECT_EQ(r.status, RsStatus::kUncorrectable);
      EXPECT_EQ(rx, received);
      EXPECT_FALSE(rs.IsCodeword(rx));
    }
  }
  Bytes msg = RandomMessage(rng, 11, 16);
  msg[3] = 0x10;
  Bytes out(15, 0x07);
  EXPECT_EQ(rs.Encode(msg, out), RsStatus::kUncorrectable);
  EXPECT_EQ(out, Bytes(15, 0x07));
}

// @verifies REQ-TG-010
TEST(ReedSolomon, InvalidParametersGiveAnInvalidCode) {
  const RsParams bad[] = {
      {8, 0x11B, 66, 50},  // field polynomial not primitive
      {8, 0x11D, 66, 66},  // k >= n
      {8, 0x11D, 66, 0},   // k = 0
      {8, 0x11D, 256, 200},  // n > q - 1
      {4, 0x13, 16, 10},   // n > q - 1
      {8, 0x11D, 100, 67},   // n - k = 33 > kMaxParity
      {9, 0x211, 300, 250},  // m out of range
  };
  for (const RsParams& p : bad) {
    const ReedSolomon rs(p);
    EXPECT_FALSE(rs.valid()) << "n=" << p.n << " k=" << p.k;
    EXPECT_EQ(rs.t(), 0U);
    Bytes cw(p.n, 0);
    EXPECT_EQ(rs.Decode(cw).status, RsStatus::kBadLength);
    EXPECT_EQ(rs.Encode(Bytes(p.k, 0), cw), RsStatus::kBadLength);
    EXPECT_FALSE(rs.IsCodeword(cw));
  }
  EXPECT_TRUE(ReedSolomon(RsParams{8, 0x11D, 255, 223}).valid());  // n - k = 32 = kMaxParity
}

}  // namespace
