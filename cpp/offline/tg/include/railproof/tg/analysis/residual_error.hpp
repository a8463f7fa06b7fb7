// Offline analysis: residual error of the telegram layer's link coding (REQ-TG-019;
// D5 §6, §6.3; digest §1.7 and §2). Normal C++ (may allocate, throws std::invalid_argument
// on bad input); not part of the runtime.
//
// ---------------------------------------------------------------------------------------
// 1. Code and decoder. RS(n,k) over GF(q), q = 2^m, is MDS: minimum distance d = n-k+1.
//    The runtime decoder (railproof::tg::ReedSolomon) is a strict bounded-distance
//    decoder of radius t = floor((d-1)/2) = floor((n-k)/2): it outputs the unique codeword
//    within Hamming distance t of the received word if there is one, and otherwise
//    declares the word uncorrectable (verified exhaustively for RS(7,3) in the unit tests).
//
// 2. Weight distribution (MDS closed form, e.g. MacWilliams & Sloane ch. 11, Thm 6):
//        A_0 = 1,  A_w = 0 for 0 < w < d,
//        A_w = C(n,w) * sum_{j=0}^{w-d} (-1)^j C(w,j) (q^(w-d+1-j) - 1)   for d <= w <= n,
//    and sum_{w>=d} A_w = q^k - 1.
//
// 3. Channel. Bits are in error independently with probability p_b; a symbol of m bits is
//    wrong with p_s = 1 - (1-p_b)^m, independently of the other symbols, and a wrong symbol
//    takes each of the q-1 other values with equal probability (an approximation: with
//    independent bit errors, one-bit symbol errors are more likely than others; the
//    uniform model is the standard one for this computation, D5 §6.3). A given error
//    vector e of Hamming weight h then has probability
//        P(e) = (p_s/(q-1))^h (1-p_s)^(n-h).
//
// 4. Outcomes per block. By linearity assume the all-zero codeword was sent; the received
//    word is e. Decoding radius spheres are disjoint (2t < d), so exactly one of:
//      correct        wt(e) <= t:           P_c = sum_{h=0}^{t} C(n,h) p_s^h (1-p_s)^(n-h)
//      mis-correction e within t of some codeword c != 0:
//                     P_m = sum_{w=d}^{n} A_w sum_h N(w,h) (p_s/(q-1))^h (1-p_s)^(n-h)
//      detected       otherwise:            P_u = sum_h U_h (p_s/(q-1))^h (1-p_s)^(n-h),
//                     U_h = C(n,h)(q-1)^h - [h<=t] C(n,h)(q-1)^h - sum_w A_w N(w,h) >= 0.
//
// 5. N(w,h): the number of vectors of weight h at distance <= t from a FIXED codeword c of
//    weight w (it depends on w only). Split the n positions into the w support positions
//    of c and the n-w zero positions of c. A vector v is described by
//      i  support positions where v equals c                (distance 0, weight 1),
//      j  support positions where v is non-zero and != c    (distance 1, weight 1; q-2 values),
//      l  support positions where v is zero                 (distance 1, weight 0),
//      u  zero positions of c where v is non-zero           (distance 1, weight 1; q-1 values),
//    with i + j + l = w. Weight h = i + j + u, distance s = j + l + u = (w - i) + u.
//        N(w,h) = sum over i, j, u with i + j + u = h, (w - i) + u <= t, 0 <= j <= w - i,
//                 u <= n - w  of  C(w,i) C(w-i,j) (q-2)^j C(n-w,u) (q-1)^u.
//    Since w >= d > 2t, every contribution has i >= w - t > t: a mis-correction needs at
//    least w - t symbol errors that exactly hit a neighbour's values.
//
//    Computed exactly in the same way (no subtraction of nearly equal numbers for P_c and
//    P_m; P_u is summed from the non-negative counts U_h), all in long double, which keeps
//    ~19 significant digits and an exponent range down to 1e-4951 — far below any figure
//    here, so no log-space is needed. The check P_c + P_m + P_u = 1 is a unit test.
//
// 6. Frame. A frame is B blocks, each decoded independently. RS delivers a wrong frame if no
//    block is detected and at least one is mis-corrected:
//        P_frame_rs = (P_c + P_m)^B - P_c^B = sum_{j=1}^{B} C(B,j) P_m^j P_c^(B-j)  (<= B P_m).
//    ASSUMPTION (frame check): a wrong frame passes the CRC-16 with probability 2^-16.
//    ASSUMPTION (authentication): a wrong frame passes the 128-bit Poly1305 tag check with
//    probability tag_pass (default 2^-128, the ideal 128-bit tag). The proven bound for an
//    adversary choosing the modification is 8*ceil(L/16)/2^106 per attempt (L = bytes
//    authenticated); a random, key-independent corruption is covered by the same bound, so
//    the rigorous figure is larger than the default by 2^25 * ceil(L/16) (override with
//    tag_pass / --tag-pass). Either way the MAC term is negligible against the target.
//        P_undetected_crc     = P_frame_rs * 2^-16
//        P_undetected_crc_mac = P_frame_rs * 2^-16 * tag_pass
//
// 7. Per hour. Telegrams per hour = bit_rate / bits_per_frame * 3600 with
//    bits_per_frame = B * n * m: the number of frames a channel running back-to-back at the
//    given bit rate carries in one hour (an upper bound on the real telegram rate, e.g.
//    7200 /h for the 500 ms ground cycle). Rate = P_undetected * telegrams per hour.
//    To first order this is independent of B (B P_m per frame, 1/B as many frames).
//    REQ-TG-019 compares the CRC+RS figure (without the MAC) and the full figure with the
//    target residual_target_per_h (1e-9 /h, D5 §6).
// ---------------------------------------------------------------------------------------
#pragma once

#include <string>
#include <vector>

namespace railproof::tg::analysis {

// RS(n,k) over GF(2^m). Valid: 2 <= m <= 8, 1 <= k < n <= 2^m - 1.
struct CodeSpec {
  unsigned n;
  unsigned k;
  unsigned m;
};

// Throws std::invalid_argument with a one-line reason if the code is not valid.
// @implements REQ-TG-019
void ValidateCode(const CodeSpec& code);

// Binomial coefficient C(n, r) as long double (exact below 2^64); 0 if r > n.
// @implements REQ-TG-019
long double Binomial(unsigned n, unsigned r);

// A_0..A_n of the MDS code (index = weight).
// @implements REQ-TG-019
std::vector<long double> MdsWeightDistribution(const CodeSpec& code);

// N(w, h): vectors of weight h within distance t of a fixed word of weight w (section 5).
// @implements REQ-TG-019
long double SphereCount(const CodeSpec& code, unsigned w, unsigned h, unsigned t);

// Number of error vectors of weight h, per outcome (section 4). Sums to C(n,h)(q-1)^h.
struct WeightClassCounts {
  long double correct;
  long double miscorrect;
  long double detected;
};
// Index h = 0..n. Independent of the channel; the probabilities follow by weighting each
// class with (p_s/(q-1))^h (1-p_s)^(n-h).
// @implements REQ-TG-019
std::vector<WeightClassCounts> CountsByErrorWeight(const CodeSpec& code);

// Symbol error probability p_s = 1 - (1 - p_b)^m, accurate for tiny p_b.
// @implements REQ-TG-019
long double SymbolErrorProbability(long double p_b, unsigned m);

struct BlockOutcome {
  long double p_symbol;         // p_s
  long double p_correct;        // P_c
  long double p_miscorrect;     // P_m
  long double p_uncorrectable;  // P_u (detected by the decoder)
};
// Per-block probabilities for symbol error probability p_s in [0, 1].
// @implements REQ-TG-019
BlockOutcome BlockOutcomeForSymbolErrorProbability(const CodeSpec& code, long double p_s);

struct ResidualConfig {
  CodeSpec code;
  unsigned blocks;            // B, RS blocks per frame (>= 1)
  double bit_rate_bps;        // > 0
  double target_per_hour;     // > 0
  long double crc_pass;       // 2^-16
  long double tag_pass;       // 2^-128 unless overridden
};

struct ResidualResult {
  double ber;
  BlockOutcome block;
  long double p_frame_rs_wrong;         // RS delivers a wrong frame (section 6)
  long double p_frame_rs_rejected;      // at least one block detected uncorrectable
  long double p_undetected_frame_crc;   // after the CRC
  long double p_undetected_frame_crc_mac;  // after the CRC and the tag
  long double telegrams_per_hour;
  long double per_hour_crc;
  long double per_hour_crc_mac;
  bool meets_target_crc;
  bool meets_target_crc_mac;
};

// Throws std::invalid_argument on a bad configuration or ber outside [0, 1].
// @implements REQ-TG-019
ResidualResult ComputeResidual(const ResidualConfig& config, double ber);

// Deterministic JSON document (no time stamps) for results/analysis/residual_error.json.
// @implements REQ-TG-019
std::string ResidualReportJson(const ResidualConfig& config,
                               const std::vector<ResidualResult>& results);

// Human-readable table.
// @implements REQ-TG-019
std::string ResidualReportTable(const ResidualConfig& config,
                                const std::vector<ResidualResult>& results);

}  // namespace railproof::tg::analysis
