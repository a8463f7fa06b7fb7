// Seeded faults as mutant schemata (spec/design/seeded-faults.md). A fault site reads
//
//   if (RAILPROOF_FAULT(FAULT_LC_STALE_CONFIRMATION)) { <faulty> } else { <correct> }
//
// or the same as a conditional expression. In the production build RAILPROOF_FAULT(x) is the
// constant false: the faulty branch is dead code the compiler removes, the fault name is not
// even evaluated, and no selector exists in the binary. Only the test-only *_faults variants
// of a module (compiled with RAILPROOF_SEEDED_FAULTS, linked into the fault test executables)
// ask the selector, which reads the environment variable RAILPROOF_SEEDED_FAULT once.
#pragma once

#if defined(RAILPROOF_SEEDED_FAULTS)
#include "railproof/generated/seeded_faults.hpp"

namespace railproof::core {
// True iff `fault` is the one selected by RAILPROOF_SEEDED_FAULT (test builds only).
bool SeededFaultActive(SeededFault fault) noexcept;
}  // namespace railproof::core

#define RAILPROOF_FAULT(name) (::railproof::core::SeededFaultActive(::railproof::core::SeededFault::name))
#else
#define RAILPROOF_FAULT(name) false
#endif
