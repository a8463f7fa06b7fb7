// Corpus replay for builds without libFuzzer (the g++ ASan+UBSan preset): every file named
// on the command line, or every file of a directory named there (in name order), runs once
// through the fuzz target's LLVMFuzzerTestOneInput, under the sanitizers of the build. The
// oracles of the target trap on a violation, so a failing input ends the run with a non-zero
// status. Prints "railproof-fuzz-replay: N inputs" on success.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

// The byte mutator of a fuzzing engine: a replay never mutates (custom mutators that call it
// are only used while fuzzing).
extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* /*data*/, std::size_t /*size*/, std::size_t /*max_size*/) {
  std::fprintf(stderr, "railproof-fuzz-replay: error: mutation requested in a replay build\n");
  std::abort();
}

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  std::vector<fs::path> inputs;
  for (int i = 1; i < argc; ++i) {
    const fs::path p(argv[i]);
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
      for (const auto& e : fs::directory_iterator(p, ec)) {
        if (e.is_regular_file()) {
          inputs.push_back(e.path());
        }
      }
    } else if (fs::is_regular_file(p, ec)) {
      inputs.push_back(p);
    } else {
      std::fprintf(stderr, "railproof-fuzz-replay: error: %s: no such file or directory\n", argv[i]);
      return 2;
    }
  }
  if (inputs.empty()) {
    std::fprintf(stderr, "railproof-fuzz-replay: error: no input (usage: %s CORPUS_DIR_OR_FILE...)\n",
                 argc > 0 ? argv[0] : "replay");
    return 2;
  }
  std::sort(inputs.begin(), inputs.end());
  for (const fs::path& p : inputs) {
    std::ifstream in(p, std::ios::binary);
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in.good() && !in.eof()) {
      std::fprintf(stderr, "railproof-fuzz-replay: error: %s: cannot read\n", p.c_str());
      return 2;
    }
    LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
  }
  std::printf("railproof-fuzz-replay: %zu inputs\n", inputs.size());
  return 0;
}
