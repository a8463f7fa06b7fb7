// ToString of a dense enum (enumerators 0..N-1) against the expected names in declaration
// order; the value after the last must give the fallback ("INVALID"). The names of the
// vectors, the reports and the evidence come from these functions.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstddef>

namespace railproof::testing {

template <typename E, std::size_t N>
void ExpectEnumNames(const std::array<const char*, N>& names, const char* fallback = "INVALID") {
  for (std::size_t i = 0; i < N; ++i) {
    EXPECT_STREQ(ToString(static_cast<E>(i)), names[i]) << "enumerator " << i;
  }
  EXPECT_STREQ(ToString(static_cast<E>(N)), fallback) << "one past the last enumerator";
}

}  // namespace railproof::testing
