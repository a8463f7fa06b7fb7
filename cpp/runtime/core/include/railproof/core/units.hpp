// Integer units of the runtime modules and the ranges every runtime input is checked
// against (spec/design/br.md §2, REQ-BR-008). Units: positions and lengths in mm (int64),
// speeds in mm/s, accelerations in mm/s^2, times in ms, gradients in permille x 10. The
// ranges keep every intermediate product of the pattern and arrival-time arithmetic inside
// int64 (see cpp/runtime/br/src/patterns.cpp, "magnitudes").
#pragma once

#include <cstddef>
#include <cstdint>

namespace railproof::core {

inline constexpr std::int64_t kMaxPositionMm = 10'000'000'000;      // |line coordinate| (10,000 km)
inline constexpr std::int64_t kMaxPositionErrorMm = 10'000'000;     // front / rear error (10 km)
inline constexpr std::int64_t kMaxMeasuredSpeedMmS = 1'000'000;     // measured speed v_m
inline constexpr std::int64_t kMaxLimitMmS = 1'000'000;             // restriction limit
inline constexpr std::int64_t kMaxGradientX10 = 1'000;              // |gradient| (100 permille)
inline constexpr std::int64_t kMaxTrainLengthMm = 10'000'000;
inline constexpr std::int64_t kMaxAccelerationMmS2 = 20'000;        // accel_max, beta_e, beta_n7
inline constexpr std::int64_t kMaxTimeMs = 60'000;                  // every supervision time / lead
inline constexpr std::int64_t kMaxSpeedAllowanceMmS = 100'000;      // overspeed, abs speed error
inline constexpr std::size_t kMaxProfileCapacity = 4'096;           // segments of one profile

}  // namespace railproof::core
