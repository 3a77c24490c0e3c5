#pragma once
// Helpers of the platform-config reader tests: load a config written to a temporary file, or get its IoError.
#include <gtest/gtest.h>

#include <string>

#include "io/error.hpp"
#include "io/odometry/odometry_config_io.hpp"
#include "support/temp_dir.hpp"

namespace drover::io::test_config {

inline std::string shipped(const std::string& name) { return std::string(DROVER_SOURCE_DIR) + "/config/" + name; }

inline bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// Writes `text` to a fresh file in `dir` and loads it.
inline pipeline::OdometryConfig load(const test::TempDir& dir, const std::string& text) {
  const auto path = dir / "odometry.yaml";
  test::writeText(path, text);
  return loadOdometryConfig(path.string());
}

// The IoError message of loading `text` (a failed expectation when it loads).
inline std::string errorOf(const test::TempDir& dir, const std::string& text) {
  try {
    load(dir, text);
  } catch (const IoError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an IoError for:\n" << text;
  return {};
}

}  // namespace drover::io::test_config
