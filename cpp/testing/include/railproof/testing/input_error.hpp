// Checks of the offline tools' bad-input errors (offline::InputError): the message is one
// line, starts with the file it names and contains every fragment (entry path, reason).
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "railproof/offline/line.hpp"

namespace railproof::testing {

// Expects `run` to throw offline::InputError "<file>: ..." in one line with every fragment.
inline void ExpectInputError(const std::function<void()>& run, const std::string& file,
                             const std::vector<std::string>& fragments) {
  try {
    run();
    ADD_FAILURE() << "no error for " << (fragments.empty() ? file : fragments.front());
  } catch (const offline::InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(file + ": ", 0), 0U) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
    for (const auto& f : fragments) {
      EXPECT_NE(msg.find(f), std::string::npos) << "'" << f << "' not in: " << msg;
    }
  }
}

}  // namespace railproof::testing
