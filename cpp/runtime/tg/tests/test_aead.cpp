// Unit tests of the payload AEAD (ChaCha20-Poly1305 IETF, libsodium) and the per-telegram
// nonce (spec/design/tg.md §1, §3).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <new>
#include <set>
#include <span>
#include <string_view>
#include <vector>

#include "railproof/tg/aead.hpp"
#include "railproof/tg/telegram.hpp"

namespace railproof::tg {
namespace {

std::array<std::uint8_t, kKeyBytes> KeyBytes(std::uint8_t first) {
  std::array<std::uint8_t, kKeyBytes> k{};
  for (std::size_t i = 0; i < kKeyBytes; ++i) {
    k[i] = static_cast<std::uint8_t>(first + i);
  }
  return k;
}

// @verifies REQ-TG-007
TEST(Aead, CryptoInitSucceedsAndIsIdempotent) {
  EXPECT_EQ(CryptoInit(), AeadStatus::kOk);
  EXPECT_EQ(CryptoInit(), AeadStatus::kOk);
}

// RFC 8439 §2.8.2 test vector: the primitive is the IETF ChaCha20-Poly1305 AEAD.
// @verifies REQ-TG-007
TEST(Aead, MatchesRfc8439Vector) {
  const LinkKey key(KeyBytes(0x80));
  const Nonce nonce = {0x07, 0x00, 0x00, 0x00, 0x40, 0x41, 0x42, 0x43, 0x44, 0x45, 0x46, 0x47};
  const std::array<std::uint8_t, 12> aad = {0x50, 0x51, 0x52, 0x53, 0xc0, 0xc1, 0xc2, 0xc3, 0xc4, 0xc5, 0xc6, 0xc7};
  constexpr std::string_view kText =
      "Ladies and Gentlemen of the class of '99: If I could offer you only one tip for the "
      "future, sunscreen would be it.";
  std::vector<std::uint8_t> plain(kText.begin(), kText.end());
  ASSERT_EQ(plain.size(), 114U);
  const std::vector<std::uint8_t> expected_ct = {
      0xd3, 0x1a, 0x8d, 0x34, 0x64, 0x8e, 0x60, 0xdb, 0x7b, 0x86, 0xaf, 0xbc, 0x53, 0xef, 0x7e, 0xc2,
      0xa4, 0xad, 0xed, 0x51, 0x29, 0x6e, 0x08, 0xfe, 0xa9, 0xe2, 0xb5, 0xa7, 0x36, 0xee, 0x62, 0xd6,
      0x3d, 0xbe, 0xa4, 0x5e, 0x8c, 0xa9, 0x67, 0x12, 0x82, 0xfa, 0xfb, 0x69, 0xda, 0x92, 0x72, 0x8b,
      0x1a, 0x71, 0xde, 0x0a, 0x9e, 0x06, 0x0b, 0x29, 0x05, 0xd6, 0xa5, 0xb6, 0x7e, 0xcd, 0x3b, 0x36,
      0x92, 0xdd, 0xbd, 0x7f, 0x2d, 0x77, 0x8b, 0x8c, 0x98, 0x03, 0xae, 0xe3, 0x28, 0x09, 0x1b, 0x58,
      0xfa, 0xb3, 0x24, 0xe4, 0xfa, 0xd6, 0x75, 0x94, 0x55, 0x85, 0x80, 0x8b, 0x48, 0x31, 0xd7, 0xbc,
      0x3f, 0xf4, 0xde, 0xf0, 0x8e, 0x4b, 0x7a, 0x9d, 0xe5, 0x76, 0xd2, 0x65, 0x86, 0xce, 0xc6, 0x4b,
      0x61, 0x16};
  const std::array<std::uint8_t, kTagBytes> expected_tag = {0x1a, 0xe1, 0x0b, 0x59, 0x4f, 0x09, 0xe2, 0x6a,
                                                            0x7e, 0x90, 0x2e, 0xcb, 0xd0, 0x60, 0x06, 0x91};
  std::vector<std::uint8_t> ct(plain.size());
  std::array<std::uint8_t, kTagBytes> tag{};
  ASSERT_EQ(Seal(key, nonce, aad, plain, ct, tag), AeadStatus::kOk);
  EXPECT_EQ(ct, expected_ct);
  EXPECT_EQ(tag, expected_tag);
  std::vector<std::uint8_t> back(plain.size());
  ASSERT_EQ(Open(key, nonce, aad, ct, tag, back), AeadStatus::kOk);
  EXPECT_EQ(back, plain);
}

// @verifies REQ-TG-007
TEST(Aead, AnyChangeFailsAuthenticationAndWipesOutput) {
  const LinkKey key(KeyBytes(1));
  const Nonce nonce = DeriveNonce(TelegramType::kControl, 1, 42, 5);
  const std::array<std::uint8_t, 5> ad = {1, 2, 3, 4, 5};
  const std::array<std::uint8_t, 7> plain = {10, 20, 30, 40, 50, 60, 70};
  std::array<std::uint8_t, 7> ct{};
  std::array<std::uint8_t, kTagBytes> tag{};
  ASSERT_EQ(Seal(key, nonce, ad, plain, ct, tag), AeadStatus::kOk);
  std::array<std::uint8_t, 7> out{};

  auto expect_reject = [&](const LinkKey& k, const Nonce& n, std::span<const std::uint8_t> a,
                           std::span<const std::uint8_t> c, std::span<const std::uint8_t, kTagBytes> t) {
    out.fill(0xAA);
    EXPECT_EQ(Open(k, n, a, c, t, out), AeadStatus::kAuthFailed);
    EXPECT_TRUE(std::all_of(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(c.size()),
                            [](std::uint8_t b) { return b == 0; }));
  };
  expect_reject(LinkKey(KeyBytes(2)), nonce, ad, ct, tag);
  expect_reject(key, DeriveNonce(TelegramType::kControl, 1, 42, 6), ad, ct, tag);
  auto ad2 = ad;
  ad2[4] ^= 1;
  expect_reject(key, nonce, ad2, ct, tag);
  expect_reject(key, nonce, std::span<const std::uint8_t>(ad).first(4), ct, tag);
  auto ct2 = ct;
  ct2[0] ^= 0x80;
  expect_reject(key, nonce, ad, ct2, tag);
  expect_reject(key, nonce, ad, std::span<const std::uint8_t>(ct).first(6), tag);
  auto tag2 = tag;
  tag2[15] ^= 1;
  expect_reject(key, nonce, ad, ct, tag2);

  out.fill(0);
  ASSERT_EQ(Open(key, nonce, ad, ct, tag, out), AeadStatus::kOk);
  EXPECT_EQ(out, plain);
}

// @verifies REQ-TG-007
TEST(Aead, EmptyPayloadStillAuthenticatesAssociatedData) {
  const LinkKey key(KeyBytes(9));
  const Nonce nonce = DeriveNonce(TelegramType::kPosition, 42, 1, 77);
  const std::array<std::uint8_t, 3> ad = {7, 8, 9};
  std::array<std::uint8_t, kTagBytes> tag{};
  ASSERT_EQ(Seal(key, nonce, ad, {}, {}, tag), AeadStatus::kOk);
  EXPECT_EQ(Open(key, nonce, ad, {}, tag, {}), AeadStatus::kOk);
  auto ad2 = ad;
  ad2[0] = 0;
  EXPECT_EQ(Open(key, nonce, ad2, {}, tag, {}), AeadStatus::kAuthFailed);
}

// @verifies REQ-TG-018
TEST(Aead, ShortOutputBuffersAreBadLength) {
  const LinkKey key(KeyBytes(3));
  const Nonce nonce{};
  const std::array<std::uint8_t, 4> plain = {1, 2, 3, 4};
  std::array<std::uint8_t, 3> small{};
  std::array<std::uint8_t, kTagBytes> tag{};
  EXPECT_EQ(Seal(key, nonce, {}, plain, small, tag), AeadStatus::kBadLength);
  std::array<std::uint8_t, 4> ct{};
  ASSERT_EQ(Seal(key, nonce, {}, plain, ct, tag), AeadStatus::kOk);
  EXPECT_EQ(Open(key, nonce, {}, ct, tag, small), AeadStatus::kBadLength);
}

// @verifies REQ-TG-011
TEST(Aead, NonceLayoutIsTypeSrcDstZeroSeq) {
  const Nonce n = DeriveNonce(TelegramType::kPosition, 0x1234, 0xABCD, 0x89ABCDEFU);
  const Nonce expected = {0x02, 0x12, 0x34, 0xAB, 0xCD, 0x00, 0x00, 0x00, 0x89, 0xAB, 0xCD, 0xEF};
  EXPECT_EQ(n, expected);
  TelegramHeader h{};
  h.version = kVersion;
  h.type = TelegramType::kPosition;
  h.src = 0x1234;
  h.dst = 0xABCD;
  h.seq = 0x89ABCDEFU;
  h.echo = 99;
  h.timestamp_ms = 12345;
  EXPECT_EQ(DeriveNonce(h), expected);
}

// @verifies REQ-TG-011
TEST(Aead, NonceDiffersWhenTypeSourceDestinationOrSequenceDiffers) {
  const Nonce base = DeriveNonce(TelegramType::kControl, 1, 42, 1000);
  EXPECT_NE(DeriveNonce(TelegramType::kPosition, 1, 42, 1000), base);
  EXPECT_NE(DeriveNonce(TelegramType::kControl, 2, 42, 1000), base);
  EXPECT_NE(DeriveNonce(TelegramType::kControl, 1, 43, 1000), base);
  EXPECT_NE(DeriveNonce(TelegramType::kControl, 1, 42, 1001), base);
  // Ground and train of one link never share a nonce: the type and the id order differ.
  EXPECT_NE(DeriveNonce(TelegramType::kPosition, 42, 1, 1000), base);
  // One key epoch: every sequence number of a sender gives a distinct nonce; sample the
  // low, high and wrap-around ranges of the 32-bit counter.
  std::set<Nonce> seen;
  for (std::uint32_t i = 0; i < 2048; ++i) {
    seen.insert(DeriveNonce(TelegramType::kControl, 1, 42, i));
    seen.insert(DeriveNonce(TelegramType::kControl, 1, 42, 0xFFFFFC00U + i));  // wraps
    seen.insert(DeriveNonce(TelegramType::kControl, 1, 42, i << 20U));
  }
  // 2048 low values, 1024 new ones before the wrap (the rest repeat 0..1023) and 2047
  // shifted ones (0 repeats): each distinct sequence number gave a distinct nonce.
  EXPECT_EQ(seen.size(), 2048U + 1024U + 2047U);
  // Each sequence-number byte lands in its own nonce byte (no byte is dropped).
  for (std::uint32_t shift = 0; shift < 32; shift += 8) {
    EXPECT_NE(DeriveNonce(TelegramType::kControl, 1, 42, 1000U ^ (1U << shift)), base) << shift;
  }
}

// @verifies REQ-TG-007
TEST(Aead, LinkKeyKeepsBytesAndWipesThemOnDestruction) {
  const auto bytes = KeyBytes(0x40);
  {
    const LinkKey key(bytes);
    EXPECT_TRUE(std::equal(bytes.begin(), bytes.end(), key.Bytes().begin()));
    const LinkKey copy = key;
    EXPECT_TRUE(std::equal(bytes.begin(), bytes.end(), copy.Bytes().begin()));
  }
  alignas(LinkKey) std::array<unsigned char, sizeof(LinkKey)> storage{};
  auto* key = new (storage.data()) LinkKey(bytes);
  ASSERT_TRUE(std::equal(bytes.begin(), bytes.end(), key->Bytes().begin()));
  key->~LinkKey();
  EXPECT_TRUE(std::all_of(storage.begin(), storage.end(), [](unsigned char b) { return b == 0; }));
}

}  // namespace
}  // namespace railproof::tg
