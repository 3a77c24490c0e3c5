#pragma once
// Asserts that a call throws io::IoError whose message holds every given fragment (file, record, reason).
#include <gtest/gtest.h>

#include <initializer_list>
#include <string>

#include "io/error.hpp"

namespace drover::test {

template <typename F>
void expectIoError(F&& f, std::initializer_list<std::string> fragments) {
  try {
    f();
    FAIL() << "expected IoError";
  } catch (const io::IoError& e) {
    for (const auto& s : fragments) EXPECT_NE(std::string(e.what()).find(s), std::string::npos) << e.what();
  }
}

}  // namespace drover::test
