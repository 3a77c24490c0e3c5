#pragma once
// Access to ../shared (real third-party data and models). Tests that need it skip with a clear message when
// the folder is absent; CI has it, so there they always run.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace drover::test {

inline std::filesystem::path sharedDir() { return std::filesystem::path(DROVER_SHARED_DIR); }
inline std::filesystem::path sharedData(const std::string& rel) { return sharedDir() / "data" / rel; }

}  // namespace drover::test

// Skips the current test when a shared file or folder is missing, naming it.
#define DROVER_REQUIRE_SHARED(path)                                                                  \
  do {                                                                                               \
    if (!std::filesystem::exists(path))                                                              \
      GTEST_SKIP() << "shared data not found: " << (path) << " (tests on real data need ../shared)"; \
  } while (0)
