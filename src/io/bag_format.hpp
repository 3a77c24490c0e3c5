#pragma once
// ROS1 bag v2.0 container format (http://wiki.ros.org/Bags/Format/2.0), read without a ROS install.
//
// A bag is "#ROSBAG V2.0\n" followed by records: <header_len u32><header><data_len u32><data>, where the header
// is a list of <field_len u32><name>=<value> and the field "op" (u8) gives the record type. Chunks hold
// (possibly compressed) connection and message data records; each chunk is followed by one index data record per
// connection in it; at index_pos (from the bag header) come all connection records and one chunk info record per
// chunk. Every length read from the file is checked against the file (or chunk) size before it is used, so a
// corrupt or truncated bag gives an IoError, never a crash, a hang or a huge allocation.
#include <cstdint>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "io/bag_decompress.hpp"
#include "types/time.hpp"

namespace drover::io::bag {

enum class Op : std::uint8_t {
  kMessageData = 0x02,
  kBagHeader = 0x03,
  kIndexData = 0x04,
  kChunk = 0x05,
  kChunkInfo = 0x06,
  kConnection = 0x07,
};

// The name=value fields of a record header (or of a connection header, which uses the same encoding).
// Getters throw IoError naming `file` and `where` when a field is missing or has the wrong size.
class Fields {
 public:
  Fields(const std::uint8_t* data, std::size_t size, std::string file, std::string where);
  bool has(const std::string& name) const;
  const std::string& raw(const std::string& name) const;
  std::uint8_t u8(const std::string& name) const;
  std::uint32_t u32(const std::string& name) const;
  std::uint64_t u64(const std::string& name) const;
  Time time(const std::string& name) const;  // ROS time: sec u32 + nsec u32 -> ns
  Op op() const { return static_cast<Op>(u8("op")); }
  const std::string& where() const { return where_; }

 private:
  std::vector<std::pair<std::string, std::string>> fields_;
  std::string file_, where_;
};

// Where one record lies in a byte range (file or decompressed chunk).
struct RecordSpan {
  std::uint64_t header_begin = 0;  // first byte of the header
  std::uint64_t data_begin = 0;    // first byte of the data
  std::uint32_t data_len = 0;
  std::uint64_t end() const { return data_begin + data_len; }
};

struct Connection {
  std::uint32_t id = 0;
  std::string topic, type, md5sum;
};

struct Chunk {
  std::uint64_t record_pos = 0;   // file offset of the chunk record
  std::uint64_t data_begin = 0;   // file offset of the (compressed) chunk data
  std::uint32_t data_len = 0;     // compressed size [bytes]
  std::uint32_t size = 0;         // uncompressed size [bytes]
  std::string compression;        // none | bz2 | lz4
};

// One message in the index: record time and where its message data record lies (offset into the
// decompressed chunk).
struct IndexEntry {
  Time time = 0;
  std::uint32_t conn = 0;
  std::uint32_t chunk = 0;   // index into BagIndex::chunks
  std::uint32_t offset = 0;  // [bytes] into the decompressed chunk
};

struct BagIndex {
  std::vector<Connection> connections;
  std::vector<Chunk> chunks;
  std::vector<IndexEntry> entries;  // sorted by (time, chunk position, offset): record-time order
  // Unindexed bags (index_pos = 0, recording not closed cleanly) are indexed by scanning their chunks; an
  // incomplete last record (the recorder stopped while writing it) is then left out.
  bool scanned = false;
  std::uint64_t unread_tail_bytes = 0;  // [bytes] at the end of a scanned bag not read
};

// Random access to one bag file. Holds the most recently decompressed chunk only, so memory stays bounded by
// the largest chunk however long the bag is.
class BagFile {
 public:
  explicit BagFile(std::string path);  // opens and checks the magic line
  const std::string& path() const { return path_; }
  std::uint64_t size() const { return size_; }

  // Reads the bag header, the connection and chunk info records and every chunk's index data records.
  BagIndex readIndex();

  // Data of the message data record `entry` points to, inside the cached decompressed chunk (valid until the
  // next call). Checks the record's op and connection against the index.
  std::pair<const std::uint8_t*, std::size_t> messageData(const BagIndex& index, const IndexEntry& entry);
  // The same data, copied. From an uncompressed chunk only the record is read (not the chunk), so visiting a
  // topic of small messages (the ground truth) up front reads a few hundred bytes per message, not the bag.
  std::vector<std::uint8_t> copyMessageData(const BagIndex& index, const IndexEntry& entry);

 private:
  void read(std::uint64_t pos, void* out, std::size_t n, const std::string& what);
  // Reads the record header at `pos`; `where` names it in errors.
  std::pair<Fields, RecordSpan> readRecord(std::uint64_t pos, const std::string& where);
  std::vector<std::uint8_t> readData(const RecordSpan& span, const std::string& what);
  void readChunkIndex(BagIndex& index, std::uint32_t chunk_no, std::uint32_t conn_records);
  BagIndex scanIndex(std::uint64_t pos);
  void scanChunk(BagIndex& index, std::uint32_t chunk_no);
  bool recordFits(std::uint64_t pos);  // the record at pos lies entirely inside the file
  static void sortEntries(BagIndex& index);
  Connection connectionFromRecord(const Fields& record, const std::uint8_t* data, std::size_t size,
                                  const std::string& where) const;
  void describeChunk(Chunk& chunk, const Fields& f, const RecordSpan& span, const std::string& where) const;
  const std::vector<std::uint8_t>& chunkData(const BagIndex& index, std::uint32_t chunk_no);

  std::string path_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
  std::int64_t cached_chunk_ = -1;
  std::vector<std::uint8_t> chunk_buffer_;
  std::vector<std::uint8_t> compressed_buffer_;
  ChunkDecompressor decompressor_;
};

// Parses the record at `pos` of an in-memory byte range (decompressed chunk); bounds-checked.
std::pair<Fields, RecordSpan> parseRecord(const std::uint8_t* data, std::size_t size, std::uint64_t pos,
                                          const std::string& file, const std::string& where);

}  // namespace drover::io::bag
