#pragma once
// Decompression of ROS1 bag chunks. "bz2" is a bzip2 stream; "lz4" is what roslz4 writes, which is the standard
// LZ4 frame format (magic 0x184D2204), so liblz4's LZ4F API reads it.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace drover::io::bag {

// Decompresses chunks; keeps its LZ4 context (and the context's 4 MiB block buffer) across chunks, because
// allocating and faulting in a fresh one per ~1 MB chunk made lz4 bags read ~10x slower than uncompressed ones.
class ChunkDecompressor {
 public:
  ChunkDecompressor();
  ~ChunkDecompressor();
  ChunkDecompressor(const ChunkDecompressor&) = delete;
  ChunkDecompressor& operator=(const ChunkDecompressor&) = delete;

  // Decompresses `n` bytes of chunk data into `out`, which is resized to `size` (the chunk header's uncompressed
  // size). Throws IoError(file, where, ...) for an unknown compression, corrupt data, or output whose length
  // differs from `size`.
  void decompress(const std::string& compression, const std::uint8_t* in, std::size_t n, std::uint32_t size,
                  std::vector<std::uint8_t>& out, const std::string& file, const std::string& where);

 private:
  void lz4(const std::uint8_t* in, std::size_t n, std::vector<std::uint8_t>& out, const std::string& file,
           const std::string& where);
  struct Lz4Context;
  std::unique_ptr<Lz4Context> lz4_;  // wraps LZ4F_dctx, kept out of this header
};

// Compressions this reader understands, for checks at index time.
bool isKnownCompression(const std::string& compression);

}  // namespace drover::io::bag
