// Private to the ground unit's sources (cpp/runtime/mb/src/wayside/ground*.cpp): constants
// and allocation-free helpers shared by the sections of the ground cycle.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>

#include "railproof/mb/wayside/ground.hpp"

namespace railproof::mb::wayside::ground_detail {

constexpr std::uint32_t kNoSlot = std::numeric_limits<std::uint32_t>::max();
constexpr std::int64_t kPlusInf = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMinusInf = std::numeric_limits<std::int64_t>::min();
constexpr std::int64_t kPpm = 1'000'000;
constexpr std::int64_t kMsPerS = 1'000;

// ceil(a / b) for a >= 0, b > 0.
constexpr std::int64_t CeilDiv(std::int64_t a, std::int64_t b) noexcept { return (a + b - 1) / b; }

// In-place, non-recursive, allocation-free sort (heap sort).
template <typename T, typename Less>
void HeapSort(std::span<T> v, Less less) noexcept {
  std::make_heap(v.begin(), v.end(), less);
  std::sort_heap(v.begin(), v.end(), less);
}

inline bool ValidSectionList(std::span<const Section> list, std::int64_t length_mm, std::size_t& entry) noexcept {
  for (std::size_t i = 0; i < list.size(); ++i) {
    const Section& s = list[i];
    const bool bad = s.begin_mm < 0 || s.end_mm > length_mm || s.begin_mm >= s.end_mm ||
                     (i > 0 && s.begin_mm < list[i - 1].end_mm);
    if (bad) {
      entry = i;
      return false;
    }
  }
  return true;
}

// False (entry = its index) if an element of `list` (points, routes, handovers) repeats the
// id of an earlier one.
template <typename T>
bool UniqueIds(std::span<const T> list, std::size_t& entry) noexcept {
  for (std::size_t i = 0; i < list.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (list[j].id == list[i].id) {
        entry = i;
        return false;
      }
    }
  }
  return true;
}


// A command adding an entry to a list of the ground (possessions, speed restrictions,
// unequipped occupancies): kInvalidRange if its arguments are not `valid`, kCapacityExceeded
// if the list is full, else make(id) with the next id is added: kAccepted with that id.
template <typename T, typename Make>
CommandResult AddWithNextId(FixedVector<T>& list, std::uint32_t& next_id, bool valid, Make make) noexcept {
  if (!valid) {
    return CommandResult{CommandStatus::kInvalidRange, 0};
  }
  if (list.Full()) {
    return CommandResult{CommandStatus::kCapacityExceeded, 0};
  }
  const std::uint32_t id = next_id++;
  (void)list.PushBack(make(id));
  return CommandResult{CommandStatus::kAccepted, id};
}

// A command removing the entry whose id_of(entry) is `id` from such a list: kAccepted, or
// kUnknownId if there is none.
template <typename T, typename IdOf>
CommandStatus EraseById(FixedVector<T>& list, std::uint32_t id, IdOf id_of) noexcept {
  for (std::size_t i = 0; i < list.Size(); ++i) {
    if (id_of(list[i]) == id) {
      list.EraseAt(i);
      return CommandStatus::kAccepted;
    }
  }
  return CommandStatus::kUnknownId;
}

template <typename T>
bool AllocateFull(FixedVector<T>& v, std::size_t n) noexcept {
  return v.Allocate(n) && v.Resize(n);
}

}  // namespace railproof::mb::wayside::ground_detail
