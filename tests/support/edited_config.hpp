#pragma once
// A shipped platform config with some of its text replaced, for CLI tests that change a setting (the detector,
// the render's rays) the way a user would edit their copy.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "support/temp_dir.hpp"

namespace drover::test {

// The shipped config `name` with each `from` replaced by its `to`, written into `dir`; a `from` the config no longer
// holds is a failed expectation.
inline std::string editedConfig(const std::string& name, const std::filesystem::path& dir,
                                const std::vector<std::pair<std::string, std::string>>& edits) {
  std::ifstream in(std::string(DROVER_SOURCE_DIR) + "/config/" + name);
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  for (const auto& [from, to] : edits) {
    const auto at = yaml.find(from);
    EXPECT_NE(at, std::string::npos) << name << " no longer has '" << from << "'";
    if (at != std::string::npos) yaml.replace(at, from.size(), to);
  }
  const std::filesystem::path out = dir / name;
  writeText(out, yaml);
  return out.string();
}

}  // namespace drover::test
