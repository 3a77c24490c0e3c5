#include "io/bag_format.hpp"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <unordered_set>

#include "io/bag_decompress.hpp"
#include "io/error.hpp"

namespace drover::io::bag {
namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::size_t kMagicLen = sizeof(kMagic) - 1;
// Record headers are a few hundred bytes (connection headers with message definitions a few KiB); a larger
// value is corruption, and refusing it avoids allocating gigabytes for a bogus length.
constexpr std::uint32_t kMaxHeaderLen = 16u << 20;
// rosbag closes a chunk at 768 KiB unless one message is larger; 1 GiB bounds allocations from corrupt sizes.
constexpr std::uint32_t kMaxChunkSize = 1u << 30;

template <typename T>
T load(const void* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));  // the format is little-endian, as are the hosts we build for
  return v;
}

std::string at(std::uint64_t pos) { return "at byte " + std::to_string(pos); }

}  // namespace

Fields::Fields(const std::uint8_t* data, std::size_t size, std::string file, std::string where)
    : file_(std::move(file)), where_(std::move(where)) {
  std::size_t pos = 0;
  while (pos < size) {
    if (size - pos < 4) fail(file_, where_, "header field length is cut off");
    const std::uint32_t len = load<std::uint32_t>(data + pos);
    pos += 4;
    if (len > size - pos)
      fail(file_, where_, "header field of " + std::to_string(len) + " bytes runs past the header's end");
    const auto* begin = reinterpret_cast<const char*>(data + pos);
    const auto* eq = static_cast<const char*>(std::memchr(begin, '=', len));
    if (eq == nullptr || eq == begin) fail(file_, where_, "header field without 'name='");
    fields_.emplace_back(std::string(begin, eq), std::string(eq + 1, begin + len));
    pos += len;
  }
}

bool Fields::has(const std::string& name) const {
  return std::any_of(fields_.begin(), fields_.end(), [&](const auto& f) { return f.first == name; });
}

const std::string& Fields::raw(const std::string& name) const {
  for (const auto& f : fields_)
    if (f.first == name) return f.second;
  fail(file_, where_, "record header has no field '" + name + "'");
}

namespace {
template <typename T>
T fixed(const Fields& f, const std::string& name, const std::string& file) {
  const std::string& v = f.raw(name);
  if (v.size() != sizeof(T))
    fail(file, f.where(), "header field '" + name + "' has " + std::to_string(v.size()) + " bytes, expected " +
                              std::to_string(sizeof(T)));
  return load<T>(v.data());
}
}  // namespace

std::uint8_t Fields::u8(const std::string& name) const { return fixed<std::uint8_t>(*this, name, file_); }
std::uint32_t Fields::u32(const std::string& name) const { return fixed<std::uint32_t>(*this, name, file_); }
std::uint64_t Fields::u64(const std::string& name) const { return fixed<std::uint64_t>(*this, name, file_); }

Time Fields::time(const std::string& name) const {
  const std::uint64_t v = u64(name);
  const auto sec = static_cast<std::uint32_t>(v & 0xffffffffu), nsec = static_cast<std::uint32_t>(v >> 32);
  if (nsec >= kNanosPerSecond) fail(file_, where_, "time field '" + name + "' has nsec >= 1e9");
  return static_cast<Time>(sec) * kNanosPerSecond + nsec;
}

std::pair<Fields, RecordSpan> parseRecord(const std::uint8_t* data, std::size_t size, std::uint64_t pos,
                                          const std::string& file, const std::string& where) {
  if (pos > size || size - pos < 4) fail(file, where, "record starts past the end of its chunk");
  const std::uint32_t header_len = load<std::uint32_t>(data + pos);
  if (header_len > size - pos - 4 || size - pos - 4 - header_len < 4)
    fail(file, where, "record header length " + std::to_string(header_len) + " runs past the end of its chunk");
  Fields fields(data + pos + 4, header_len, file, where);
  RecordSpan span{pos, pos + 8 + header_len, load<std::uint32_t>(data + pos + 4 + header_len)};
  if (span.data_len > size - span.data_begin)
    fail(file, where, "record data length " + std::to_string(span.data_len) + " runs past the end of its chunk");
  return {std::move(fields), span};
}

BagFile::BagFile(std::string path) : path_(std::move(path)), in_(path_, std::ios::binary) {
  // A folder opens as a stream on Linux and then fails every read: say what it is instead.
  if (std::filesystem::is_directory(path_)) fail(path_, "", "is a folder, not a ROS bag file");
  if (!in_) fail(path_, "", "cannot open bag file");
  in_.seekg(0, std::ios::end);
  size_ = static_cast<std::uint64_t>(in_.tellg());
  char magic[kMagicLen] = {};
  if (size_ < kMagicLen) fail(path_, "", "file is too short to be a ROS bag");
  read(0, magic, kMagicLen, "magic line");
  if (std::memcmp(magic, kMagic, kMagicLen) != 0) {
    if (std::memcmp(magic, "#ROSBAG V", 9) == 0) {
      std::string version(magic, kMagicLen - 1);  // shown on one line, whatever bytes it holds
      for (char& c : version)
        if (c < 0x20 || c > 0x7e) c = '?';
      fail(path_, "", "unsupported bag version '" + version + "' (only 2.0 is supported)");
    }
    fail(path_, "", "not a ROS bag: the file does not start with '#ROSBAG V2.0'");
  }
}

void BagFile::read(std::uint64_t pos, void* out, std::size_t n, const std::string& what) {
  if (pos > size_ || n > size_ - pos)
    fail(path_, what, "needs bytes " + std::to_string(pos) + ".." + std::to_string(pos + n) + " but the file has " +
                          std::to_string(size_) + " bytes (truncated bag?)");
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(pos));
  in_.read(static_cast<char*>(out), static_cast<std::streamsize>(n));
  if (static_cast<std::size_t>(in_.gcount()) != n) fail(path_, what, "read error");
}

std::pair<Fields, RecordSpan> BagFile::readRecord(std::uint64_t pos, const std::string& where) {
  std::uint32_t header_len = 0;
  read(pos, &header_len, 4, where);
  if (header_len > kMaxHeaderLen || header_len > size_ - pos - 4)
    fail(path_, where, "record header length " + std::to_string(header_len) + " " + at(pos) +
                           " runs past the end of the file (" + std::to_string(size_) + " bytes)");
  std::vector<std::uint8_t> header(header_len);
  read(pos + 4, header.data(), header_len, where);
  RecordSpan span{pos, pos + 8 + header_len, 0};
  read(pos + 4 + header_len, &span.data_len, 4, where);
  if (span.data_len > size_ - span.data_begin)
    fail(path_, where, "record data length " + std::to_string(span.data_len) + " " + at(span.data_begin) +
                           " runs past the end of the file (" + std::to_string(size_) +
                           " bytes): truncated or corrupt bag");
  return {Fields(header.data(), header.size(), path_, where), span};
}

std::vector<std::uint8_t> BagFile::readData(const RecordSpan& span, const std::string& what) {
  std::vector<std::uint8_t> data(span.data_len);
  read(span.data_begin, data.data(), data.size(), what);
  return data;
}

BagIndex BagFile::readIndex() {
  auto [header, header_span] = readRecord(kMagicLen, "bag header");
  if (header.op() != Op::kBagHeader) fail(path_, "bag header", "first record is not a bag header");
  const std::uint64_t index_pos = header.u64("index_pos");
  const std::uint32_t conn_count = header.u32("conn_count"), chunk_count = header.u32("chunk_count");
  if (index_pos == 0) return scanIndex(header_span.end());  // recording not closed cleanly
  if (index_pos < header_span.end() || index_pos >= size_)
    fail(path_, "bag header", "index_pos " + std::to_string(index_pos) + " lies outside the file (" +
                                  std::to_string(size_) + " bytes): truncated bag?");
  // Each record takes at least 8 bytes, which bounds the counts by what the file can hold.
  if ((static_cast<std::uint64_t>(conn_count) + chunk_count) * 8 > size_ - index_pos)
    fail(path_, "bag header", "conn_count/chunk_count do not fit in the file: truncated bag?");

  BagIndex index;
  std::uint64_t pos = index_pos;
  for (std::uint32_t i = 0; i < conn_count; ++i) {
    const std::string where = "connection record " + std::to_string(i) + " " + at(pos);
    auto [f, span] = readRecord(pos, where);
    if (f.op() != Op::kConnection) fail(path_, where, "expected a connection record (op 0x07)");
    const std::vector<std::uint8_t> data = readData(span, where);
    index.connections.push_back(connectionFromRecord(f, data.data(), data.size(), where));
    pos = span.end();
  }
  std::vector<std::uint32_t> conns_per_chunk;
  for (std::uint32_t i = 0; i < chunk_count; ++i) {
    const std::string where = "chunk info record " + std::to_string(i) + " " + at(pos);
    auto [f, span] = readRecord(pos, where);
    if (f.op() != Op::kChunkInfo) fail(path_, where, "expected a chunk info record (op 0x06)");
    if (f.u32("ver") != 1) fail(path_, where, "unsupported chunk info version " + std::to_string(f.u32("ver")));
    const std::uint32_t count = f.u32("count");
    if (span.data_len != static_cast<std::uint64_t>(count) * 8)
      fail(path_, where, "data length does not match its connection count");
    Chunk chunk;
    chunk.record_pos = f.u64("chunk_pos");
    index.chunks.push_back(chunk);
    conns_per_chunk.push_back(count);
    pos = span.end();
  }
  for (std::uint32_t i = 0; i < chunk_count; ++i) readChunkIndex(index, i, conns_per_chunk[i]);
  sortEntries(index);
  return index;
}

void BagFile::sortEntries(BagIndex& index) {
  std::vector<std::uint64_t> chunk_pos;
  for (const Chunk& c : index.chunks) chunk_pos.push_back(c.record_pos);
  std::sort(index.entries.begin(), index.entries.end(), [&](const IndexEntry& a, const IndexEntry& b) {
    if (a.time != b.time) return a.time < b.time;
    if (a.chunk != b.chunk) return chunk_pos[a.chunk] < chunk_pos[b.chunk];
    return a.offset < b.offset;
  });
}

Connection BagFile::connectionFromRecord(const Fields& record, const std::uint8_t* data, std::size_t size,
                                         const std::string& where) const {
  const Fields header(data, size, path_, where + " connection header");
  return {record.u32("conn"), record.raw("topic"), header.raw("type"),
          header.has("md5sum") ? header.raw("md5sum") : "*"};
}

void BagFile::describeChunk(Chunk& chunk, const Fields& f, const RecordSpan& span, const std::string& where) const {
  if (f.op() != Op::kChunk) fail(path_, where, "expected a chunk record (op 0x05)");
  chunk.compression = f.raw("compression");
  chunk.size = f.u32("size");
  chunk.data_begin = span.data_begin;
  chunk.data_len = span.data_len;
  if (!isKnownCompression(chunk.compression))
    fail(path_, where, "unknown chunk compression '" + chunk.compression + "' (expected none, bz2 or lz4)");
  // LZ4 expands at most ~255x, which bounds the buffer a corrupt size field can make us allocate.
  const bool implausible = chunk.size > kMaxChunkSize ||
                           (chunk.compression == "lz4" && chunk.size > 255ull * chunk.data_len + 1024) ||
                           (chunk.compression == "none" && chunk.size != chunk.data_len);
  if (implausible)
    fail(path_, where, "chunk size " + std::to_string(chunk.size) + " is implausible for " +
                           std::to_string(chunk.data_len) + " bytes of " + chunk.compression + " data");
}

void BagFile::readChunkIndex(BagIndex& index, std::uint32_t chunk_no, std::uint32_t conn_records) {
  Chunk& chunk = index.chunks[chunk_no];
  const std::string where = "chunk " + std::to_string(chunk_no) + " " + at(chunk.record_pos);
  if (chunk.record_pos < kMagicLen || chunk.record_pos >= size_)
    fail(path_, where, "chunk position lies outside the file (" + std::to_string(size_) + " bytes): truncated bag?");
  auto [f, span] = readRecord(chunk.record_pos, where);
  describeChunk(chunk, f, span, where);

  std::unordered_set<std::uint32_t> known;
  for (const Connection& c : index.connections) known.insert(c.id);
  std::uint64_t pos = span.end();
  for (std::uint32_t j = 0; j < conn_records; ++j) {
    const std::string iwhere = "index data record " + std::to_string(j) + " of " + where;
    auto [fi, ispan] = readRecord(pos, iwhere);
    if (fi.op() != Op::kIndexData) fail(path_, iwhere, "expected an index data record (op 0x04)");
    if (fi.u32("ver") != 1) fail(path_, iwhere, "unsupported index data version " + std::to_string(fi.u32("ver")));
    const std::uint32_t conn = fi.u32("conn"), count = fi.u32("count");
    if (!known.count(conn)) fail(path_, iwhere, "refers to unknown connection " + std::to_string(conn));
    if (ispan.data_len != static_cast<std::uint64_t>(count) * 12)
      fail(path_, iwhere, "data length does not match its message count");
    const std::vector<std::uint8_t> data = readData(ispan, iwhere);
    for (std::uint32_t k = 0; k < count; ++k) {
      const std::uint8_t* e = data.data() + 12 * k;
      const std::uint32_t sec = load<std::uint32_t>(e), nsec = load<std::uint32_t>(e + 4);
      const std::uint32_t offset = load<std::uint32_t>(e + 8);
      if (nsec >= kNanosPerSecond || offset >= chunk.size)
        fail(path_, iwhere, "entry " + std::to_string(k) + " has an invalid time or an offset outside the chunk");
      index.entries.push_back({static_cast<Time>(sec) * kNanosPerSecond + nsec, conn, chunk_no, offset});
    }
    pos = ispan.end();
  }
}

const std::vector<std::uint8_t>& BagFile::chunkData(const BagIndex& index, std::uint32_t chunk_no) {
  if (cached_chunk_ == static_cast<std::int64_t>(chunk_no)) return chunk_buffer_;
  cached_chunk_ = -1;  // stays invalid if decompression throws
  const Chunk& chunk = index.chunks[chunk_no];
  const std::string where = "chunk " + std::to_string(chunk_no) + " " + at(chunk.record_pos);
  compressed_buffer_.resize(chunk.data_len);
  read(chunk.data_begin, compressed_buffer_.data(), chunk.data_len, where);
  decompressor_.decompress(chunk.compression, compressed_buffer_.data(), compressed_buffer_.size(), chunk.size,
                           chunk_buffer_, path_, where);
  cached_chunk_ = chunk_no;
  return chunk_buffer_;
}

namespace {
std::string messageWhere(const BagIndex& index, const IndexEntry& entry) {
  return "message record at offset " + std::to_string(entry.offset) + " of chunk " + std::to_string(entry.chunk) +
         " " + at(index.chunks[entry.chunk].record_pos);
}
}  // namespace

std::vector<std::uint8_t> BagFile::copyMessageData(const BagIndex& index, const IndexEntry& entry) {
  const Chunk& chunk = index.chunks[entry.chunk];
  if (chunk.compression != "none") {
    const auto [data, size] = messageData(index, entry);
    return {data, data + size};
  }
  const std::string where = messageWhere(index, entry);
  if (entry.offset >= chunk.data_len) fail(path_, where, "offset lies outside its chunk");
  auto [f, span] = readRecord(chunk.data_begin + entry.offset, where);
  if (span.end() > chunk.data_begin + chunk.data_len) fail(path_, where, "record runs past the end of its chunk");
  if (f.op() != Op::kMessageData) fail(path_, where, "index points at a record that is not message data");
  if (f.u32("conn") != entry.conn) fail(path_, where, "message connection differs from the index");
  return readData(span, where);
}

std::pair<const std::uint8_t*, std::size_t> BagFile::messageData(const BagIndex& index, const IndexEntry& entry) {
  const std::vector<std::uint8_t>& data = chunkData(index, entry.chunk);
  const std::string where = messageWhere(index, entry);
  auto [f, span] = parseRecord(data.data(), data.size(), entry.offset, path_, where);
  if (f.op() != Op::kMessageData) fail(path_, where, "index points at a record that is not message data");
  if (f.u32("conn") != entry.conn) fail(path_, where, "message connection differs from the index");
  return {data.data() + span.data_begin, span.data_len};
}

}  // namespace drover::io::bag
