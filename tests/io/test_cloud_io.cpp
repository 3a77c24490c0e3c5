#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "io/cloud_io.hpp"
#include "io/error.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {

std::string fileText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(CloudIo, PcdRoundTripsEveryFloatExactly) {
  drover::test::TempDir dir;
  const CloudPoints points = {{1.f, -2.5f, 3.25f}, {1e-7f, 123456.f, -0.f}, {0.1f, 0.2f, 0.3f}};
  const std::string path = (dir / "map.pcd").string();
  writePcdBinary(path, points);
  const CloudPoints back = readPcdBinary(path);
  ASSERT_EQ(back.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) EXPECT_EQ(back[i], points[i]) << i;
  EXPECT_NE(fileText(path).find("POINTS 3\nDATA binary\n"), std::string::npos);
}

TEST(CloudIo, PlyHeaderDeclaresTheVertexCountAndTheBodyHasTwelveBytesEach) {
  drover::test::TempDir dir;
  const std::string path = (dir / "map.ply").string();
  writePlyBinary(path, CloudPoints(5, Eigen::Vector3f(1, 2, 3)));
  const std::string text = fileText(path);
  const std::string end = "end_header\n";
  const std::size_t body = text.find(end);
  ASSERT_NE(body, std::string::npos);
  EXPECT_NE(text.find("format binary_little_endian 1.0\ncomment written by Drover\nelement vertex 5\n"), std::string::npos) << text;
  EXPECT_EQ(text.size() - body - end.size(), 5u * 12u);
}

TEST(CloudIo, NonFinitePointIsRefusedNamingItAndNoFileIsLeft) {
  drover::test::TempDir dir;
  const std::string path = (dir / "map.pcd").string();
  CloudPoints points(3, Eigen::Vector3f::Zero());
  points[2].y() = std::numeric_limits<float>::quiet_NaN();
  try {
    writePcdBinary(path, points);
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("point 2"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(CloudIo, ReadingATextPcdIsAClearError) {
  drover::test::TempDir dir;
  const std::string path = (dir / "ascii.pcd").string();
  std::ofstream(path) << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\n"
                         "POINTS 1\nDATA ascii\n1 2 3\n";
  EXPECT_THROW(readPcdBinary(path), IoError);
}

}  // namespace
}  // namespace drover::io
