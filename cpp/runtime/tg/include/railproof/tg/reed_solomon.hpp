// Systematic Reed-Solomon code RS(n, k) over GF(2^m): the link FEC of the telegram layer
// (REQ-TG-010; D5 §6.3: RS(66,50) over GF(2^8), minimum distance 17, corrects 8 symbols).
//
// Conventions (ASM-008, spec/design/tg.md §1):
//  - generator g(x) = (x - alpha^1)(x - alpha^2)...(x - alpha^(n-k)), alpha = x = 0x02;
//  - codeword layout: data[0..k) followed by parity[k..n); symbol i is the coefficient of
//    x^(n-1-i) (the first data symbol is the highest-degree coefficient); n < 2^m - 1 is a
//    shortened code (the leading 2^m - 1 - n symbols are implicit zeros);
//  - parity = (data(x) * x^(n-k)) mod g(x).
//
// The decoder is STRICTLY bounded-distance (radius t = floor((n-k)/2)): syndromes,
// Berlekamp-Massey, Chien search, Forney. A correction is accepted only if the error
// locator degree L <= t, exactly L distinct roots lie in the n code positions, every error
// value is non-zero and the corrected word has all-zero syndromes (re-check). Otherwise
// the word is kUncorrectable and the caller's buffer is left unchanged (the decoder works
// on a local copy and commits only on success). Hence an accepted output is always a
// codeword at distance <= t from the received word.
//
// Runtime module rules: fixed capacity (kMaxN, kMaxParity), no heap, no exceptions, no
// recursion, every loop bounded by n or n-k.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "railproof/tg/galois_field.hpp"

namespace railproof::tg {

struct RsParams {
  unsigned m;               // field GF(2^m), 2 <= m <= 8
  unsigned primitive_poly;  // field polynomial including x^m
  unsigned n;               // codeword length in symbols, n <= 2^m - 1, n <= kMaxN
  unsigned k;               // data symbols, 1 <= k < n, n - k <= kMaxParity
};

enum class RsStatus : std::uint8_t {
  kOk,             // Encode: done. Decode: the word was a codeword, nothing changed.
  kCorrected,      // Decode: 1..t symbols corrected in place.
  kUncorrectable,  // Decode: no codeword within radius t (or a symbol >= 2^m); buffer unchanged.
                   // Encode: a data symbol >= 2^m; codeword unchanged.
  kBadLength,      // Span sizes do not match (k, n), or the code itself is not valid().
};

struct RsDecodeResult {
  RsStatus status;
  std::uint8_t corrected_symbols;  // number of symbols changed (0 unless kCorrected)
};

// @implements REQ-TG-010
class ReedSolomon {
 public:
  static constexpr unsigned kMaxN = 255;
  static constexpr unsigned kMaxParity = 32;

  explicit ReedSolomon(const RsParams& params) noexcept;

  [[nodiscard]] bool valid() const noexcept { return valid_; }
  [[nodiscard]] unsigned n() const noexcept { return n_; }
  [[nodiscard]] unsigned k() const noexcept { return k_; }
  // Correction radius floor((n - k) / 2); 0 if not valid().
  [[nodiscard]] unsigned t() const noexcept { return valid_ ? (n_ - k_) / 2U : 0U; }
  [[nodiscard]] const GaloisField& field() const noexcept { return gf_; }

  // Writes data (k symbols) followed by the n - k parity symbols into codeword (n symbols).
  // data may alias codeword (e.g. codeword.first(k)): it is read completely before writing.
  [[nodiscard]] RsStatus Encode(std::span<const std::uint8_t> data,
                                std::span<std::uint8_t> codeword) const noexcept;

  // Decodes codeword (n symbols) in place; see the header comment for the acceptance rules.
  [[nodiscard]] RsDecodeResult Decode(std::span<std::uint8_t> codeword) const noexcept;

  // True if word has length n, all symbols in the field and all syndromes zero.
  [[nodiscard]] bool IsCodeword(std::span<const std::uint8_t> word) const noexcept;

  // Coefficient of x^i of the generator polynomial, 0 <= i <= n - k (monic: g_{n-k} = 1).
  [[nodiscard]] std::uint8_t generator_coefficient(unsigned i) const noexcept;

 private:
  // Computes S_j = r(alpha^j), j = 1..n-k, into s[0..n-k); returns true if any is non-zero.
  bool ComputeSyndromes(const std::uint8_t* word, std::uint8_t* s) const noexcept;

  GaloisField gf_;
  unsigned n_;
  unsigned k_;
  unsigned nroots_ = 0;
  bool valid_ = false;
  std::array<std::uint8_t, kMaxParity + 1> gen_{};  // g_0 .. g_{n-k}
  std::array<std::uint16_t, kMaxParity + 1> gen_log_{};  // log g_i, GaloisField::kNoLog if 0
};

// The telegram layer's RS(66,50) over GF(2^8) with the field polynomial of the generated
// parameters (rs_n, rs_k, gf_primitive_poly). Constructed on first use; no heap.
// @implements REQ-TG-010
const ReedSolomon& Rs6650() noexcept;

}  // namespace railproof::tg
