// ChaCha20-Poly1305 IETF (libsodium) for the telegram payload; design §1 and §3.
#include "railproof/tg/aead.hpp"

#include <sodium.h>

namespace railproof::tg {

static_assert(kKeyBytes == crypto_aead_chacha20poly1305_ietf_KEYBYTES);
static_assert(kNonceBytes == crypto_aead_chacha20poly1305_ietf_NPUBBYTES);
static_assert(kTagBytes == crypto_aead_chacha20poly1305_ietf_ABYTES);

AeadStatus CryptoInit() noexcept {
  // sodium_init() returns 0 on first success, 1 if already initialised, -1 on failure.
  // The initialisation of a function-local static is thread-safe (C++11 [stmt.dcl]).
  static const bool ready = sodium_init() >= 0;
  return ready ? AeadStatus::kOk : AeadStatus::kCryptoUnavailable;
}

LinkKey::LinkKey(std::span<const std::uint8_t, kKeyBytes> bytes) noexcept : bytes_{} {
  for (std::size_t i = 0; i < kKeyBytes; ++i) {
    bytes_[i] = bytes[i];
  }
}

LinkKey::~LinkKey() { sodium_memzero(bytes_.data(), bytes_.size()); }

// @implements REQ-TG-011
Nonce DeriveNonce(TelegramType type, std::uint16_t src, std::uint16_t dst,
                  std::uint32_t seq) noexcept {
  Nonce nonce{};  // bytes 5..7 stay 0x000000
  nonce[0] = static_cast<std::uint8_t>(type);
  nonce[1] = static_cast<std::uint8_t>(src >> 8U);
  nonce[2] = static_cast<std::uint8_t>(src);
  nonce[3] = static_cast<std::uint8_t>(dst >> 8U);
  nonce[4] = static_cast<std::uint8_t>(dst);
  nonce[8] = static_cast<std::uint8_t>(seq >> 24U);
  nonce[9] = static_cast<std::uint8_t>(seq >> 16U);
  nonce[10] = static_cast<std::uint8_t>(seq >> 8U);
  nonce[11] = static_cast<std::uint8_t>(seq);
  return nonce;
}

// @implements REQ-TG-011
Nonce DeriveNonce(const TelegramHeader& header) noexcept {
  return DeriveNonce(header.type, header.src, header.dst, header.seq);
}

// @implements REQ-TG-007
AeadStatus Seal(const LinkKey& key, const Nonce& nonce, std::span<const std::uint8_t> associated,
                std::span<const std::uint8_t> plaintext, std::span<std::uint8_t> ciphertext,
                std::span<std::uint8_t, kTagBytes> tag) noexcept {
  if (CryptoInit() != AeadStatus::kOk) {
    return AeadStatus::kCryptoUnavailable;  // GCOVR_EXCL_LINE defensive: sodium_init failed
  }
  if (ciphertext.size() < plaintext.size()) {
    return AeadStatus::kBadLength;
  }
  // libsodium declares the ciphertext pointer non-null even for an empty payload.
  std::uint8_t empty = 0;
  unsigned char* const c = plaintext.empty() ? &empty : ciphertext.data();
  unsigned long long tag_len = 0;
  const int rc = crypto_aead_chacha20poly1305_ietf_encrypt_detached(
      c, tag.data(), &tag_len, plaintext.data(), plaintext.size(),
      associated.data(), associated.size(), nullptr, nonce.data(), key.Bytes().data());
  if (rc != 0 || tag_len != kTagBytes) {
    return AeadStatus::kCryptoUnavailable;  // GCOVR_EXCL_LINE defensive: libsodium never fails here
  }
  return AeadStatus::kOk;
}

// @implements REQ-TG-007
AeadStatus Open(const LinkKey& key, const Nonce& nonce, std::span<const std::uint8_t> associated,
                std::span<const std::uint8_t> ciphertext, std::span<const std::uint8_t, kTagBytes> tag,
                std::span<std::uint8_t> plaintext) noexcept {
  if (plaintext.size() < ciphertext.size()) {
    return AeadStatus::kBadLength;
  }
  const auto out = plaintext.first(ciphertext.size());
  if (CryptoInit() != AeadStatus::kOk) {
    sodium_memzero(out.data(), out.size());  // GCOVR_EXCL_LINE defensive: sodium_init failed
    return AeadStatus::kCryptoUnavailable;   // GCOVR_EXCL_LINE
  }
  // libsodium verifies the tag before it decrypts and writes nothing on failure; the
  // output is still wiped so that no caller can read stale bytes from a rejected telegram.
  // libsodium declares the ciphertext pointer non-null even for an empty payload.
  const std::uint8_t empty = 0;
  const unsigned char* const c = ciphertext.empty() ? &empty : ciphertext.data();
  const int rc = crypto_aead_chacha20poly1305_ietf_decrypt_detached(
      out.data(), nullptr, c, ciphertext.size(), tag.data(), associated.data(),
      associated.size(), nonce.data(), key.Bytes().data());
  if (rc != 0) {
    sodium_memzero(out.data(), out.size());
    return AeadStatus::kAuthFailed;
  }
  return AeadStatus::kOk;
}

}  // namespace railproof::tg
