// The host of the test drivers' precompiled header (cpp/testing/CMakeLists.txt): CMake
// compiles the header once with this target's options, and every unit-test and
// conformance-runner object reuses it. Nothing else belongs here.
