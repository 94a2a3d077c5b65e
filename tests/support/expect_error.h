// Checks that a call fails with a farfield::Error whose message names what it should (file, place, option).
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::test {

// Runs `call`, which must throw farfield::Error whose message holds every one of `parts`.
template <typename F>
void expectErrorMentions(F call, const std::vector<std::string>& parts) {
  try {
    call();
    ADD_FAILURE() << "expected farfield::Error mentioning " << parts.back();
  } catch (const Error& e) {
    for (const std::string& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << "'" << part << "' in: " << e.what();
  }
}

}  // namespace farfield::test
