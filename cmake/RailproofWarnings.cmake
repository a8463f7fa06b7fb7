# Common warning and sanitizer flags, applied per target through railproof_options.
add_library(railproof_options INTERFACE)
target_compile_options(railproof_options INTERFACE -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion)
if(RAILPROOF_WERROR)
  target_compile_options(railproof_options INTERFACE -Werror)
endif()
if(RAILPROOF_SANITIZE)
  target_compile_options(railproof_options INTERFACE -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
  target_link_options(railproof_options INTERFACE -fsanitize=address,undefined)
endif()
# Runtime (safety) modules additionally forbid exceptions and RTTI.
add_library(railproof_runtime_options INTERFACE)
target_link_libraries(railproof_runtime_options INTERFACE railproof_options)
target_compile_options(railproof_runtime_options INTERFACE -fno-exceptions -fno-rtti)

# libFuzzer builds (RAILPROOF_FUZZ, clang): the flags every instrumented target and library
# shares. Line tables are all a sanitizer report or a crash reproducer needs.
set(RAILPROOF_FUZZ_COMMON_FLAGS -fno-sanitize-recover=all -fno-omit-frame-pointer -gline-tables-only -O1)
set(RAILPROOF_FUZZ_LIBRARY_FLAGS -fsanitize=fuzzer-no-link,address,undefined ${RAILPROOF_FUZZ_COMMON_FLAGS})
set(RAILPROOF_FUZZ_TARGET_FLAGS -fsanitize=fuzzer,address,undefined ${RAILPROOF_FUZZ_COMMON_FLAGS})
set(RAILPROOF_FUZZ_LINK_FLAGS -fsanitize=fuzzer,address,undefined)

# Test drivers (unit-test and conformance-runner objects) in an optimised build: they only
# feed inputs to the libraries under test, which keep the build's optimisation, so they are
# compiled without optimisation (about a third of the compile time of an optimised object full
# of GoogleTest and JSON templates). The sanitizer build (Debug) is unoptimised anyway.
add_library(railproof_test_driver_options INTERFACE)
target_compile_options(railproof_test_driver_options INTERFACE $<$<CONFIG:RelWithDebInfo,Release,MinSizeRel>:-O0>)
