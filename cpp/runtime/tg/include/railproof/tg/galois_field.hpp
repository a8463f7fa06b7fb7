// Galois field GF(2^m), 2 <= m <= 8, for the link Reed-Solomon code (REQ-TG-010).
//
// Runtime module rules: no heap, no exceptions, no recursion, bounded loops. Elements are
// represented as bytes in polynomial basis (bit i = coefficient of x^i); alpha = x (0x02)
// is the primitive element. The construction checks that the given field polynomial is
// primitive (ASM-008: 0x11D for GF(2^8)) and reports the verdict through valid(); an
// invalid field answers every operation with 0 and must not be used.
#pragma once

#include <array>
#include <cstdint>

namespace railproof::tg {

// @implements REQ-TG-010
class GaloisField {
 public:
  static constexpr unsigned kMinM = 2;
  static constexpr unsigned kMaxM = 8;
  static constexpr unsigned kMaxSize = 1U << kMaxM;  // largest q
  // log() of zero or of a value outside the field (there is no logarithm).
  static constexpr unsigned kNoLog = kMaxSize;

  // m: extension degree; primitive_poly: field polynomial including the x^m term
  // (e.g. 0x11D = x^8+x^4+x^3+x^2+1). valid() is false if m is out of range, the
  // polynomial has the wrong degree, or it is not primitive.
  GaloisField(unsigned m, unsigned primitive_poly) noexcept;

  [[nodiscard]] bool valid() const noexcept { return valid_; }
  [[nodiscard]] unsigned m() const noexcept { return m_; }
  [[nodiscard]] unsigned primitive_poly() const noexcept { return poly_; }
  // Number of elements q = 2^m.
  [[nodiscard]] unsigned size() const noexcept { return q_; }
  // Order of the multiplicative group, q - 1.
  [[nodiscard]] unsigned order() const noexcept { return q_ == 0U ? 0U : q_ - 1U; }
  // True if a is an element of the field (a < q).
  [[nodiscard]] bool contains(unsigned a) const noexcept { return a < q_; }

  // Addition and subtraction are the same: bitwise XOR.
  [[nodiscard]] static constexpr std::uint8_t add(std::uint8_t a, std::uint8_t b) noexcept {
    return static_cast<std::uint8_t>(a ^ b);
  }
  // Products and quotients of field elements (a, b < q). Total functions: a zero divisor
  // or an operand outside the field yields 0 (callers that can see these check first); an
  // invalid field yields 0 for everything.
  // @implements REQ-TG-010
  // (Defined inline: they are the inner loops of the codec.)
  [[nodiscard]] std::uint8_t mul(std::uint8_t a, std::uint8_t b) const noexcept {
    if (!valid_ || a == 0U || b == 0U || a >= q_ || b >= q_) {
      return 0;
    }
    return exp_[static_cast<unsigned>(log_[a]) + log_[b]];
  }
  [[nodiscard]] std::uint8_t div(std::uint8_t a, std::uint8_t b) const noexcept {
    if (!valid_ || a == 0U || b == 0U || a >= q_ || b >= q_) {
      return 0;
    }
    return exp_[static_cast<unsigned>(log_[a]) + (q_ - 1U) - log_[b]];
  }
  // Multiplicative inverse; inv(0) = 0 (no inverse exists).
  [[nodiscard]] std::uint8_t inv(std::uint8_t a) const noexcept {
    if (!valid_ || a == 0U || a >= q_) {
      return 0;
    }
    return exp_[(q_ - 1U) - log_[a]];
  }
  // alpha^i for any i (reduced modulo q - 1).
  [[nodiscard]] std::uint8_t pow_alpha(unsigned i) const noexcept {
    return valid_ ? exp_[i % (q_ - 1U)] : std::uint8_t{0};
  }
  // Discrete logarithm base alpha in [0, q-1); kNoLog for 0 or a >= q.
  [[nodiscard]] unsigned log(std::uint8_t a) const noexcept {
    return (!valid_ || a == 0U || a >= q_) ? kNoLog : log_[a];
  }

  // Fast paths used by the decoder. Preconditions: a != 0, a < q; i < 2 (q - 1).
  [[nodiscard]] std::uint8_t exp_unchecked(unsigned i) const noexcept { return exp_[i]; }
  [[nodiscard]] unsigned log_unchecked(std::uint8_t a) const noexcept { return log_[a]; }

 private:
  unsigned m_ = 0;
  unsigned q_ = 0;
  unsigned poly_ = 0;
  bool valid_ = false;
  // exp_[i] = alpha^i for 0 <= i < 2 (q - 1): doubled so that log a + log b needs no modulo.
  std::array<std::uint8_t, 2U * (kMaxSize - 1U)> exp_{};
  // log_[a] for 1 <= a < q; log_[0] and entries >= q are unused (0).
  std::array<std::uint8_t, kMaxSize> log_{};
};

}  // namespace railproof::tg
