// Negative test of the loaders' fuzz oracle (json_fuzz.hpp): the same harness around a reader
// that does what the loaders did before they were made safe: nlohmann's exceptions escape
// (a syntax error, a missing key, a value of another type), and a rejection names the entry
// without a reason. ctest runs it on committed inputs (corpus/oracle_negative/) and expects
// the oracle to fire on each: an oracle that could not see these would pass any loader.
#include <cstddef>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "json_fuzz.hpp"
#include "railproof/offline/line.hpp"

namespace {

const std::string kFile = "negative.json";

void NaiveRead(const std::string& text) {
  const nlohmann::json doc = nlohmann::json::parse(text);  // parse_error escapes
  const auto length = doc.at("length_mm").get<std::int64_t>();  // out_of_range, type_error escape
  if (length <= 0) {
    throw railproof::offline::InputError(kFile + ": length_mm");  // no reason
  }
}

}  // namespace

RAILPROOF_FUZZ_JSON_MUTATOR()

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return railproof::fuzz::TestOneInput(kFile, data, size,
                                       [](const std::string& text) { NaiveRead(text); });
}
