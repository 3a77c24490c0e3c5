#include "io/bag_decompress.hpp"

#include <bzlib.h>
#include <lz4frame.h>

#include <cstring>
#include <memory>

#include "io/error.hpp"

namespace drover::io::bag {
namespace {

void decompressBz2(const std::uint8_t* in, std::size_t n, std::vector<std::uint8_t>& out, const std::string& file,
                   const std::string& where) {
  // bzlib counts in unsigned int; chunk sizes are u32 in the format, so this never truncates.
  auto dest_len = static_cast<unsigned int>(out.size());
  const int rc = BZ2_bzBuffToBuffDecompress(reinterpret_cast<char*>(out.data()), &dest_len,
                                            const_cast<char*>(reinterpret_cast<const char*>(in)),
                                            static_cast<unsigned int>(n), /*small=*/0, /*verbosity=*/0);
  if (rc == BZ_OUTBUFF_FULL)
    fail(file, where, "bz2 chunk decompresses to more than its header's size of " + std::to_string(out.size()) +
                          " bytes");
  if (rc != BZ_OK) fail(file, where, "corrupt bz2 chunk data (bzlib error " + std::to_string(rc) + ")");
  if (dest_len != out.size())
    fail(file, where, "bz2 chunk decompresses to " + std::to_string(dest_len) + " bytes, its header says " +
                          std::to_string(out.size()));
}

}  // namespace

bool isKnownCompression(const std::string& compression) {
  return compression == "none" || compression == "bz2" || compression == "lz4";
}

struct ChunkDecompressor::Lz4Context {
  LZ4F_dctx* ctx = nullptr;
  ~Lz4Context() {
    if (ctx != nullptr) LZ4F_freeDecompressionContext(ctx);
  }
};

ChunkDecompressor::ChunkDecompressor() : lz4_(std::make_unique<Lz4Context>()) {}
ChunkDecompressor::~ChunkDecompressor() = default;

void ChunkDecompressor::lz4(const std::uint8_t* in, std::size_t n, std::vector<std::uint8_t>& out,
                            const std::string& file, const std::string& where) {
  if (lz4_->ctx == nullptr && LZ4F_isError(LZ4F_createDecompressionContext(&lz4_->ctx, LZ4F_VERSION)))
    fail(file, where, "cannot create an LZ4 decompression context");
  LZ4F_dctx* ctx = lz4_->ctx;
  LZ4F_resetDecompressionContext(ctx);  // a previous chunk may have failed mid-frame
  std::size_t in_pos = 0, out_pos = 0;
  std::size_t hint = 1;  // LZ4F_decompress returns 0 once a frame is complete
  while (in_pos < n) {
    std::size_t in_size = n - in_pos;
    std::size_t out_size = out.size() - out_pos;
    hint = LZ4F_decompress(ctx, out.data() + out_pos, &out_size, in + in_pos, &in_size, nullptr);
    if (LZ4F_isError(hint)) fail(file, where, std::string("corrupt lz4 chunk data: ") + LZ4F_getErrorName(hint));
    in_pos += in_size;
    out_pos += out_size;
    if (hint == 0) break;
    if (in_size == 0 && out_size == 0) {
      // No progress: the output is full and the frame unfinished, i.e. more data than the header announced.
      fail(file, where, "lz4 chunk decompresses to more than its header's size of " + std::to_string(out.size()) +
                            " bytes");
    }
  }
  if (hint != 0) fail(file, where, "lz4 chunk data ends in the middle of a frame (truncated or corrupt)");
  if (out_pos != out.size())
    fail(file, where, "lz4 chunk decompresses to " + std::to_string(out_pos) + " bytes, its header says " +
                          std::to_string(out.size()));
}

void ChunkDecompressor::decompress(const std::string& compression, const std::uint8_t* in, std::size_t n,
                                   std::uint32_t size, std::vector<std::uint8_t>& out, const std::string& file,
                                   const std::string& where) {
  out.resize(size);
  if (compression == "none") {
    if (n != size)
      fail(file, where, "uncompressed chunk holds " + std::to_string(n) + " bytes, its header says " +
                            std::to_string(size));
    if (n > 0) std::memcpy(out.data(), in, n);
  } else if (compression == "bz2") {
    decompressBz2(in, n, out, file, where);
  } else if (compression == "lz4") {
    lz4(in, n, out, file, where);
  } else {
    fail(file, where, "unknown chunk compression '" + compression + "' (expected none, bz2 or lz4)");
  }
}

}  // namespace drover::io::bag
