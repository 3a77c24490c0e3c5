// ROS bag reader on damaged bags: valid fixtures (tests/io/fixtures/write_bags.py) copied, then cut or patched
// here. Every case must end in an IoError naming the bag, never a crash, a hang or silently wrong data; an
// unindexed bag (recorder killed) is read by scanning its chunks, with a warning.
#include <gtest/gtest.h>

#include <cstdint>
#include <algorithm>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "io/bag_reader.hpp"
#include "io/error.hpp"
#include "io/fixtures/bag_fixtures.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {

using test::BagFixtures;
using test::readFileText;
using test::writeFileText;

DatasetOptions allTopics() {
  DatasetOptions o;
  o.lidar_topic = "/velodyne_points";
  o.imu_topic = "/imu_raw";
  o.image_topic = "/cam/png";
  return o;
}

// Opens and reads the whole bag; returns the IoError text, or "" when the bag read without error.
std::string readError(const std::string& path) {
  try {
    BagReader reader(path, allTopics());
    while (reader.next()) {
    }
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

std::uint32_t u32At(const std::string& b, std::size_t pos) {
  std::uint32_t v;
  std::memcpy(&v, b.data() + pos, 4);
  return v;
}

void putU32(std::string& b, std::size_t pos, std::uint32_t v) { std::memcpy(b.data() + pos, &v, 4); }

// Byte offset of the first chunk record: the magic line (13 bytes), then the bag header record.
std::size_t firstChunkPos(const std::string& b) {
  const std::size_t header_len = u32At(b, 13);
  return 13 + 4 + header_len + 4 + u32At(b, 13 + 4 + header_len);
}

class CorruptBag : public ::testing::Test {
 protected:
  std::string original(const std::string& compression) { return readFileText(BagFixtures::get().bag(compression)); }
  std::string write(const std::string& bytes) {
    const std::string path = (dir_ / "corrupt.bag").string();
    writeFileText(path, bytes);
    return path;
  }
  void expectError(const std::string& bytes, const std::string& fragment) {
    const std::string path = write(bytes);
    const std::string what = readError(path);
    ASSERT_FALSE(what.empty()) << "no error for a bag expected to fail with '" << fragment << "'";
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(fragment), std::string::npos) << what;
  }
  test::TempDir dir_;
};

TEST_F(CorruptBag, FixtureReadsCleanlyBeforeDamage) {
  for (const char* c : {"none", "bz2", "lz4"}) EXPECT_EQ(readError(BagFixtures::get().bag(c).string()), "") << c;
}

TEST_F(CorruptBag, RejectsAnotherMagicLine) {
  std::string b = original("none");
  b.replace(0, 13, "#ROSBAG V1.2\n");
  expectError(b, "only 2.0");
  b.replace(0, 13, "#ROSBOG V2.0\n");
  expectError(b, "not a ROS bag");
  expectError("#ROS", "too short");
  b.replace(0, 13, "#ROSBAG V\n2.0");  // the version is shown on the error's one line
  expectError(b, "unsupported bag version '#ROSBAG V?2.' (only 2.0");
}

TEST_F(CorruptBag, RejectsBagCutInTheMiddleOfAChunk) {
  const std::string b = original("lz4");
  const std::size_t chunk = firstChunkPos(b);
  expectError(b.substr(0, chunk + 40), "truncated");
}

TEST_F(CorruptBag, RejectsBagCutAnywhere) {
  // Cuts through the header, chunks, index data and the final connection/chunk info records.
  const std::string b = original("bz2");
  for (std::size_t cut = 0; cut < b.size(); cut += 389) {
    SCOPED_TRACE("cut at byte " + std::to_string(cut));
    EXPECT_NE(readError(write(b.substr(0, cut))), "");
  }
  EXPECT_NE(readError(write(b.substr(0, b.size() - 1))), "");
}

TEST_F(CorruptBag, RejectsChunkDataLengthLargerThanTheFile) {
  std::string b = original("lz4");
  const std::size_t chunk = firstChunkPos(b);
  putU32(b, chunk + 4 + u32At(b, chunk), 0xfffffff0u);
  expectError(b, "runs past the end of the file");
}

TEST_F(CorruptBag, RejectsChunkDataLengthOffByOne) {
  std::string b = original("none");
  const std::size_t pos = firstChunkPos(b);
  const std::size_t len_pos = pos + 4 + u32At(b, pos);
  putU32(b, len_pos, u32At(b, len_pos) + 1);
  EXPECT_NE(readError(write(b)), "");
}

TEST_F(CorruptBag, RejectsUnknownCompression) {
  std::string b = original("lz4");
  const std::string from = "compression=lz4", to = "compression=zst";
  std::size_t n = 0;
  for (std::size_t p = b.find(from); p != std::string::npos; p = b.find(from, p + 1), ++n) b.replace(p, to.size(), to);
  ASSERT_GT(n, 0u);
  expectError(b, "unknown chunk compression 'zst'");
}

std::string withoutIndex(std::string b) {
  const std::size_t p = b.find("index_pos=");
  EXPECT_NE(p, std::string::npos);
  b.replace(p + 10, 8, std::string(8, '\0'));
  return b;
}

// (kind, time) of every measurement, and the reader's warnings.
std::pair<std::vector<std::pair<std::size_t, Time>>, std::vector<std::string>> stream(const std::string& path) {
  BagReader reader(path, allTopics());
  std::vector<std::pair<std::size_t, Time>> out;
  while (auto m = reader.next()) out.emplace_back(m->index(), measurementTime(*m));
  return {out, reader.warnings()};
}

TEST_F(CorruptBag, ReadsUnindexedBagByScanningItsChunks) {
  for (const char* c : {"none", "bz2", "lz4"}) {
    SCOPED_TRACE(c);
    const auto indexed = stream(BagFixtures::get().bag(c).string());
    const auto scanned = stream(write(withoutIndex(original(c))));
    EXPECT_EQ(scanned.first, indexed.first);
    ASSERT_EQ(scanned.second.size(), 1u);
    EXPECT_NE(scanned.second[0].find("not indexed"), std::string::npos);
  }
}

TEST_F(CorruptBag, ReadsTheCompleteChunksOfAnUnindexedBagCutShort) {
  const std::string b = withoutIndex(original("lz4"));
  const auto full = stream(write(b)).first;
  const auto cut = stream(write(b.substr(0, b.size() / 2)));
  ASSERT_GT(cut.first.size(), 0u);
  ASSERT_LT(cut.first.size(), full.size());
  // What was read is the start of the full stream, less messages whose chunk was cut off.
  for (const auto& m : cut.first) EXPECT_NE(std::find(full.begin(), full.end(), m), full.end());
  ASSERT_EQ(cut.second.size(), 1u);
  EXPECT_NE(cut.second[0].find("were incomplete"), std::string::npos) << cut.second[0];
}

TEST_F(CorruptBag, RejectsIndexPositionBeyondTheFile) {
  std::string b = original("none");
  const std::size_t p = b.find("index_pos=");
  const std::uint64_t beyond = b.size() + 100;
  std::memcpy(b.data() + p + 10, &beyond, 8);
  expectError(b, "outside the file");
}

TEST_F(CorruptBag, RejectsDamagedCompressedChunkData) {
  for (const char* c : {"bz2", "lz4"}) {
    SCOPED_TRACE(c);
    std::string b = original(c);
    const std::size_t pos = firstChunkPos(b);
    const std::size_t data = pos + 4 + u32At(b, pos) + 4;
    for (std::size_t i = 60; i < 90; ++i) b[data + i] = static_cast<char>(b[data + i] ^ 0x5a);
    expectError(b, "corrupt " + std::string(c) + " chunk data");
  }
}

TEST_F(CorruptBag, NeverCrashesOnSingleByteDamage) {
  // Flipping any byte may go unnoticed (a float in a payload) but must never crash or hang.
  const std::string b = original("lz4");
  for (std::size_t i = 0; i < b.size(); i += 17) {
    std::string damaged = b;
    damaged[i] = static_cast<char>(damaged[i] ^ 0xff);
    readError(write(damaged));
  }
  SUCCEED();
}

}  // namespace
}  // namespace drover::io
