// Bag format building blocks: record header fields and chunk decompression (round trips through liblz4's frame
// compressor and bzlib, the formats roslz4 and rosbag's bz2 chunks use).
#include <bzlib.h>
#include <gtest/gtest.h>
#include <lz4frame.h>

#include <cstring>
#include <string>
#include <vector>

#include "io/bag_decompress.hpp"
#include "io/bag_format.hpp"
#include "io/error.hpp"

namespace drover::io::bag {
namespace {

std::vector<std::uint8_t> sample(std::size_t n) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint8_t>((i * 7919) % 251 + (i / 1000) % 3);
  return v;
}

std::vector<std::uint8_t> lz4Frame(const std::vector<std::uint8_t>& raw) {
  std::vector<std::uint8_t> out(LZ4F_compressFrameBound(raw.size(), nullptr));
  const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), raw.data(), raw.size(), nullptr);
  EXPECT_FALSE(LZ4F_isError(n));
  out.resize(n);
  return out;
}

std::vector<std::uint8_t> bz2(const std::vector<std::uint8_t>& raw) {
  std::vector<std::uint8_t> out(raw.size() + raw.size() / 100 + 600);
  auto len = static_cast<unsigned int>(out.size());
  EXPECT_EQ(BZ2_bzBuffToBuffCompress(reinterpret_cast<char*>(out.data()), &len,
                                     const_cast<char*>(reinterpret_cast<const char*>(raw.data())),
                                     static_cast<unsigned int>(raw.size()), 9, 0, 0),
            BZ_OK);
  out.resize(len);
  return out;
}

std::string errorOf(ChunkDecompressor& d, const std::string& compression, const std::vector<std::uint8_t>& in,
                    std::uint32_t size) {
  std::vector<std::uint8_t> out;
  try {
    d.decompress(compression, in.data(), in.size(), size, out, "x.bag", "chunk 0");
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

TEST(ChunkDecompressor, RoundTripsLz4FramesAndBz2Streams) {
  const auto raw = sample(300000);
  ChunkDecompressor d;
  for (const auto& [name, packed] : {std::pair{"lz4", lz4Frame(raw)}, std::pair{"bz2", bz2(raw)}}) {
    std::vector<std::uint8_t> out;
    d.decompress(name, packed.data(), packed.size(), static_cast<std::uint32_t>(raw.size()), out, "x.bag", "c");
    EXPECT_EQ(out, raw) << name;
  }
}

TEST(ChunkDecompressor, RejectsOutputOfAnotherSizeThanTheChunkHeaderSays) {
  const auto raw = sample(5000);
  ChunkDecompressor d;
  const auto n = static_cast<std::uint32_t>(raw.size());
  EXPECT_NE(errorOf(d, "lz4", lz4Frame(raw), n - 1).find("more than"), std::string::npos);
  EXPECT_NE(errorOf(d, "lz4", lz4Frame(raw), n + 1).find("decompresses to 5000 bytes"), std::string::npos);
  EXPECT_NE(errorOf(d, "bz2", bz2(raw), n - 1).find("more than"), std::string::npos);
  EXPECT_NE(errorOf(d, "bz2", bz2(raw), n + 1).find("decompresses to 5000 bytes"), std::string::npos);
  EXPECT_NE(errorOf(d, "none", raw, n + 1).find("header says"), std::string::npos);
  EXPECT_NE(errorOf(d, "zstd", raw, n).find("unknown chunk compression 'zstd'"), std::string::npos);
}

TEST(ChunkDecompressor, DecodesAGoodChunkAfterACorruptOne) {
  const auto raw = sample(100000);
  auto packed = lz4Frame(raw);
  auto bad = packed;
  bad.resize(bad.size() / 2);  // frame cut in the middle
  ChunkDecompressor d;
  EXPECT_NE(errorOf(d, "lz4", bad, static_cast<std::uint32_t>(raw.size())), "");
  EXPECT_EQ(errorOf(d, "lz4", packed, static_cast<std::uint32_t>(raw.size())), "");
}

std::string field(const std::string& name_value) {
  const auto n = static_cast<std::uint32_t>(name_value.size());
  std::string out(4, '\0');
  std::memcpy(out.data(), &n, 4);
  return out + name_value;
}

Fields parse(const std::string& bytes) {
  return Fields(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), "x.bag", "record 3");
}

TEST(BagFields, ReadsNameValueFieldsWithBinaryValues) {
  const std::string op = std::string("op=") + '\x05';
  const std::string conn = std::string("conn=") + std::string("\x07\x00\x00\x00", 4);
  const Fields f = parse(field(op) + field("compression=lz4") + field(conn) + field("topic=/a=b"));
  EXPECT_EQ(f.op(), Op::kChunk);
  EXPECT_EQ(f.raw("compression"), "lz4");
  EXPECT_EQ(f.u32("conn"), 7u);
  EXPECT_EQ(f.raw("topic"), "/a=b");  // only the first '=' separates
  EXPECT_FALSE(f.has("size"));
}

TEST(BagFields, RejectsMalformedHeaders) {
  EXPECT_THROW(parse(field("compression=lz4").substr(0, 10)), IoError);  // field runs past the header
  EXPECT_THROW(parse(field("noequals")), IoError);
  EXPECT_THROW(parse(field("=value")), IoError);
  EXPECT_THROW(parse(std::string("\x01\x00", 2)), IoError);  // length cut off
  const Fields f = parse(field("conn=ab"));
  try {
    f.u32("conn");
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("x.bag (record 3)"), std::string::npos) << e.what();
  }
  EXPECT_THROW(f.u32("missing"), IoError);
}

}  // namespace
}  // namespace drover::io::bag
