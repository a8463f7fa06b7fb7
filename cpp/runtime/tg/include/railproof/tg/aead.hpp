// Authenticated encryption of the telegram payload (design §1, §3): ChaCha20-Poly1305
// IETF from libsodium, the 21-byte header as associated data, a 16-byte detached tag and
// a nonce derived per telegram from type, source, destination and sequence number.
// Runtime module: no heap, no exceptions, typed results.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "railproof/tg/telegram.hpp"

namespace railproof::tg {

inline constexpr std::size_t kKeyBytes = 32;
inline constexpr std::size_t kNonceBytes = 12;

using Nonce = std::array<std::uint8_t, kNonceBytes>;

enum class AeadStatus : std::uint8_t {
  kOk,
  kCryptoUnavailable,  // sodium_init() failed; nothing was sealed or opened
  kBadLength,          // an output buffer is shorter than the input
  kAuthFailed,         // tag does not verify under key, nonce and associated data
};

// Initialises libsodium exactly once (thread-safe function-local static). Every Seal and
// Open calls it; callers may call it at start-up to fail early.
AeadStatus CryptoInit() noexcept;

// The secret key of one ground-train link and key epoch (ASM-TG-003). The bytes are
// wiped with sodium_memzero when the object is destroyed; copies wipe themselves too.
// @implements REQ-TG-007
class LinkKey {
 public:
  explicit LinkKey(std::span<const std::uint8_t, kKeyBytes> bytes) noexcept;
  explicit LinkKey(const std::array<std::uint8_t, kKeyBytes>& bytes) noexcept
      : LinkKey(std::span<const std::uint8_t, kKeyBytes>(bytes)) {}
  LinkKey(const LinkKey& other) noexcept = default;
  LinkKey& operator=(const LinkKey& other) noexcept = default;
  ~LinkKey();

  [[nodiscard]] std::span<const std::uint8_t, kKeyBytes> Bytes() const noexcept { return bytes_; }

 private:
  std::array<std::uint8_t, kKeyBytes> bytes_;
};

// 12-byte IETF nonce = type (1) || src (2) || dst (2) || 0x000000 (3) || seq (4), big-endian
// (design §3).
// @implements REQ-TG-011
Nonce DeriveNonce(TelegramType type, std::uint16_t src, std::uint16_t dst,
                  std::uint32_t seq) noexcept;
// @implements REQ-TG-011
Nonce DeriveNonce(const TelegramHeader& header) noexcept;

// Encrypts plaintext into ciphertext[0, plaintext.size()) and writes the tag.
// kBadLength if ciphertext is shorter than plaintext.
// @implements REQ-TG-007
AeadStatus Seal(const LinkKey& key, const Nonce& nonce, std::span<const std::uint8_t> associated,
                std::span<const std::uint8_t> plaintext, std::span<std::uint8_t> ciphertext,
                std::span<std::uint8_t, kTagBytes> tag) noexcept;

// Verifies the tag and, only if it verifies, decrypts into plaintext[0, ciphertext.size()).
// On any failure those plaintext bytes are zero. kBadLength if plaintext is too short.
// @implements REQ-TG-007
AeadStatus Open(const LinkKey& key, const Nonce& nonce, std::span<const std::uint8_t> associated,
                std::span<const std::uint8_t> ciphertext, std::span<const std::uint8_t, kTagBytes> tag,
                std::span<std::uint8_t> plaintext) noexcept;

}  // namespace railproof::tg
