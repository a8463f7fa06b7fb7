// Names of enumerators for reports, vectors and messages: ToString(e) of a dense enum
// (enumerators 0..N-1 in declaration order) is core::EnumName(e, {names in that order}).
// A value outside the enum gives the fallback ("INVALID" unless stated).
#pragma once

#include <array>
#include <cstddef>
#include <type_traits>

namespace railproof::core {

template <typename E, std::size_t N>
constexpr const char* EnumName(E value, const std::array<const char*, N>& names,
                               const char* fallback = "INVALID") noexcept {
  static_assert(std::is_enum_v<E>);
  const auto index = static_cast<std::underlying_type_t<E>>(value);
  return index >= 0 && static_cast<std::size_t>(index) < N ? names[static_cast<std::size_t>(index)] : fallback;
}

}  // namespace railproof::core
