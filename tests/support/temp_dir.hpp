#pragma once
// A fresh temporary folder per test, removed afterwards, for fixtures the tests write themselves.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

namespace drover::test {

class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info ? std::string(info->test_suite_name()) + "_" + info->name() : "drover";
    for (char& c : name) c = c == '/' ? '_' : c;  // parameterised tests: "Prefix/Suite", "Test/0"
    path_ = std::filesystem::temp_directory_path() / ("drover_" + name + "_" + std::to_string(std::random_device{}()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& rel) const { return path_ / rel; }

 private:
  std::filesystem::path path_;
};

// The whole file as bytes; empty when it cannot be read.
inline std::string readText(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void writeText(const std::filesystem::path& p, const std::string& text) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

// Writes `yaml` to dir/platform.yaml; returns its path.
inline std::string writePlatformFile(const TempDir& dir, const std::string& yaml) {
  const std::filesystem::path p = dir / "platform.yaml";
  writeText(p, yaml);
  return p.string();
}

}  // namespace drover::test
