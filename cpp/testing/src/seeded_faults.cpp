// The run-time selector of the seeded-fault (mutant schemata) builds: the fault named by the
// environment variable RAILPROOF_SEEDED_FAULT is active, every other fault is not; no variable
// (or an empty one) selects none. An unknown name aborts the run with a message, so a misspelt
// fault can never pass as "not killed" or "killed". Test-only: linked into the *_faults
// variants, never into a production module.
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string_view>

#include "railproof/core/seeded_fault.hpp"

namespace railproof::core {
namespace {

std::optional<SeededFault> ReadSelection() noexcept {
  const char* env = std::getenv("RAILPROOF_SEEDED_FAULT");
  if (env == nullptr || *env == '\0') {
    return std::nullopt;
  }
  const std::string_view name(env);
  for (std::size_t i = 0; i < kSeededFaultNames.size(); ++i) {
    if (kSeededFaultNames[i] == name) {
      std::fprintf(stderr, "railproof: seeded fault %s active\n", env);
      return static_cast<SeededFault>(i);
    }
  }
  std::fprintf(stderr, "railproof: error: RAILPROOF_SEEDED_FAULT=%s names no seeded fault of "
                       "spec/capabilities.yaml\n", env);
  std::abort();
}

}  // namespace

bool SeededFaultActive(SeededFault fault) noexcept {
  static const std::optional<SeededFault> selected = ReadSelection();
  return selected.has_value() && *selected == fault;
}

}  // namespace railproof::core
