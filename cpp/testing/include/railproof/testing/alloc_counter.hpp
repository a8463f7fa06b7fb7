// Allocation counter for the no-heap tests of the runtime modules (REQ-TG-018, REQ-MB-021).
// alloc_counter.cpp replaces the global allocation functions of the whole test binary;
// they count only between StartCountingAllocations and StopCountingAllocations, so the
// rest of the binary is unaffected. Link alloc_counter.cpp exactly once per test binary.
#pragma once

#include <cstddef>

namespace railproof::testing {

// Resets the count to zero and starts counting calls of operator new (every form).
void StartCountingAllocations() noexcept;

// Stops counting and returns the number of allocations since StartCountingAllocations.
std::size_t StopCountingAllocations() noexcept;

}  // namespace railproof::testing
