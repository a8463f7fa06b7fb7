// Unit tests of GF(2^m) arithmetic (REQ-TG-010, ASM-008). Field axioms are checked
// exhaustively for GF(2^8) (0x11D) and GF(2^4) (0x13) against a table-free reference
// multiplication (shift-and-add modulo the field polynomial).
#include <gtest/gtest.h>

#include <cstdint>

#include "railproof/generated/tg_params.hpp"
#include "railproof/tg/galois_field.hpp"

namespace {

using railproof::tg::GaloisField;

// Carry-less multiplication reduced modulo poly: independent of the exp/log tables.
unsigned RefMul(unsigned a, unsigned b, unsigned m, unsigned poly) {
  unsigned r = 0;
  for (unsigned i = 0; i < m; ++i) {
    if ((b >> i) & 1U) {
      r ^= a << i;
    }
  }
  for (unsigned bit = 2U * m; bit-- > m;) {
    if ((r >> bit) & 1U) {
      r ^= poly << (bit - m);
    }
  }
  return r;
}

std::uint8_t U8(unsigned v) { return static_cast<std::uint8_t>(v); }

void CheckFieldAxioms(unsigned m, unsigned poly) {
  const GaloisField gf(m, poly);
  ASSERT_TRUE(gf.valid());
  const unsigned q = 1U << m;
  ASSERT_EQ(gf.size(), q);
  ASSERT_EQ(gf.order(), q - 1U);
  unsigned distributivity_failures = 0;
  unsigned associativity_failures = 0;
  for (unsigned a = 0; a < q; ++a) {
    EXPECT_EQ(gf.mul(U8(a), 1), a);
    EXPECT_EQ(gf.mul(U8(a), 0), 0U);
    EXPECT_EQ(GaloisField::add(U8(a), U8(a)), 0U);
    if (a != 0U) {
      EXPECT_EQ(gf.mul(U8(a), gf.inv(U8(a))), 1U) << "a=" << a;
      EXPECT_EQ(gf.pow_alpha(gf.log(U8(a))), a);
    }
    for (unsigned b = 0; b < q; ++b) {
      const std::uint8_t ab = gf.mul(U8(a), U8(b));
      ASSERT_EQ(ab, RefMul(a, b, m, poly)) << "a=" << a << " b=" << b;
      ASSERT_EQ(ab, gf.mul(U8(b), U8(a)));
      if (b != 0U) {
        ASSERT_EQ(gf.div(ab, U8(b)), a) << "a=" << a << " b=" << b;
        ASSERT_EQ(gf.div(U8(a), U8(b)), gf.mul(U8(a), gf.inv(U8(b))));
      }
      for (unsigned c = 0; c < q; ++c) {
        // Distributivity and associativity (counted, reported once: q^3 triples).
        distributivity_failures +=
            gf.mul(U8(a), GaloisField::add(U8(b), U8(c))) != GaloisField::add(ab, gf.mul(U8(a), U8(c)));
        associativity_failures += gf.mul(ab, U8(c)) != gf.mul(U8(a), gf.mul(U8(b), U8(c)));
      }
    }
  }
  EXPECT_EQ(distributivity_failures, 0U);
  EXPECT_EQ(associativity_failures, 0U);
}

// @verifies REQ-TG-010
TEST(GaloisField, AxiomsExhaustiveGf256) {
  CheckFieldAxioms(8, static_cast<unsigned>(railproof::params::tg::gf_primitive_poly));
}

// @verifies REQ-TG-010
TEST(GaloisField, AxiomsExhaustiveGf16) { CheckFieldAxioms(4, 0x13); }

// @verifies REQ-TG-010
TEST(GaloisField, AlphaGeneratesTheMultiplicativeGroup) {
  const GaloisField gf(8, 0x11D);
  ASSERT_TRUE(gf.valid());
  EXPECT_EQ(gf.pow_alpha(0), 1U);
  EXPECT_EQ(gf.pow_alpha(1), 2U);
  EXPECT_EQ(gf.pow_alpha(8), 0x1DU);  // x^8 = x^4 + x^3 + x^2 + 1
  EXPECT_EQ(gf.pow_alpha(255), 1U);
  EXPECT_EQ(gf.pow_alpha(255 + 7), gf.pow_alpha(7));
  bool seen[256] = {};
  for (unsigned i = 0; i < 255U; ++i) {
    const unsigned v = gf.pow_alpha(i);
    ASSERT_NE(v, 0U);
    ASSERT_FALSE(seen[v]) << "alpha^" << i << " repeats";
    seen[v] = true;
    EXPECT_EQ(gf.log(static_cast<std::uint8_t>(v)), i);
  }
}

// @verifies REQ-TG-010
TEST(GaloisField, ZeroAndOutOfFieldOperandsAreTotal) {
  const GaloisField gf(4, 0x13);
  ASSERT_TRUE(gf.valid());
  EXPECT_EQ(gf.inv(0), 0U);
  EXPECT_EQ(gf.div(5, 0), 0U);
  EXPECT_EQ(gf.log(0), GaloisField::kNoLog);
  EXPECT_EQ(gf.log(16), GaloisField::kNoLog);
  EXPECT_EQ(gf.mul(16, 3), 0U);
  EXPECT_EQ(gf.inv(200), 0U);
  EXPECT_FALSE(gf.contains(16));
  EXPECT_TRUE(gf.contains(15));
}

// The construction accepts exactly the primitive polynomials: their number for degree m
// is phi(2^m - 1) / m (1, 2, 2, 6, 6, 18, 16 for m = 2..8).
// @verifies REQ-TG-010
TEST(GaloisField, AcceptsExactlyThePrimitivePolynomials) {
  const unsigned expected[] = {0, 0, 1, 2, 2, 6, 6, 18, 16};
  for (unsigned m = 2; m <= 8U; ++m) {
    unsigned count = 0;
    for (unsigned poly = 1U << m; poly < (2U << m); ++poly) {
      if (GaloisField(m, poly).valid()) {
        ++count;
      }
    }
    EXPECT_EQ(count, expected[m]) << "m=" << m;
  }
}

// @verifies REQ-TG-010
TEST(GaloisField, RejectsInvalidConstructions) {
  EXPECT_TRUE(GaloisField(8, 0x11D).valid());
  EXPECT_TRUE(GaloisField(3, 0xB).valid());
  EXPECT_FALSE(GaloisField(8, 0x11B).valid());  // AES polynomial: irreducible, not primitive
  EXPECT_FALSE(GaloisField(4, 0x1F).valid());   // x^4+x^3+x^2+x+1: irreducible, order 5
  EXPECT_FALSE(GaloisField(4, 0x15).valid());   // (x^2+x+1)^2: reducible
  EXPECT_FALSE(GaloisField(4, 0x12).valid());   // no constant term
  EXPECT_FALSE(GaloisField(8, 0x1D).valid());   // wrong degree
  EXPECT_FALSE(GaloisField(4, 0x11D).valid());  // wrong degree
  EXPECT_FALSE(GaloisField(1, 0x3).valid());    // m out of range
  EXPECT_FALSE(GaloisField(9, 0x211).valid());  // m out of range (x^9+x^4+1 is primitive)
  const GaloisField bad(8, 0x11B);
  EXPECT_EQ(bad.mul(3, 5), 0U);
  EXPECT_EQ(bad.pow_alpha(1), 0U);
  const GaloisField out_of_range(12, 0x1053);
  EXPECT_EQ(out_of_range.size(), 0U);
  EXPECT_EQ(out_of_range.order(), 0U);
}

}  // namespace
