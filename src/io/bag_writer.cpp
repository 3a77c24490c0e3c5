// ROS1 bag v2.0 writer (layout in io/bag_writer.hpp).
#include "io/bag_writer.hpp"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "io/bag_format.hpp"
#include "io/error.hpp"
#include "io/output_paths.hpp"

namespace drover::io::bag {
namespace {
namespace fs = std::filesystem;

static_assert(std::endian::native == std::endian::little, "bag fields are written in host order");

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::size_t kMagicLen = sizeof(kMagic) - 1;
constexpr std::size_t kHeaderRecordLen = 4096;  // rosbag pads the bag header's header + data to this
// Chunk offsets are uint32 and Drover's reader refuses chunks over 1 GiB: a chunk is closed before it would grow
// past this, whatever chunk_bytes says.
constexpr std::uint64_t kMaxChunk = 1u << 30;
constexpr Time kMaxRecordTime = (Time{1} << 32) * kNanosPerSecond;  // ROS time: uint32 seconds

template <typename T>
std::string packed(T v) {
  std::string s(sizeof(T), '\0');
  std::memcpy(s.data(), &v, sizeof(T));
  return s;
}

// ROS time: uint32 seconds, uint32 nanoseconds.
std::string packedTime(Time t) {
  return packed(static_cast<std::uint32_t>(t / kNanosPerSecond)) +
         packed(static_cast<std::uint32_t>(t % kNanosPerSecond));
}

// One header field: uint32 length, then "name=value".
void field(std::string& header, std::string_view name, std::string_view value) {
  header += packed(static_cast<std::uint32_t>(name.size() + 1 + value.size()));
  header.append(name).append(1, '=').append(value);
}

std::string op(Op o) { return packed(static_cast<std::uint8_t>(o)); }

// Header length, header, data length (the data follows).
std::string recordPrefix(const std::string& header, std::size_t data_len) {
  return packed(static_cast<std::uint32_t>(header.size())) + header + packed(static_cast<std::uint32_t>(data_len));
}

void appendRecord(std::string& out, const std::string& header, std::string_view data) {
  out += recordPrefix(header, data.size());
  out.append(data);
}

bool startsWithBagMagic(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  char magic[kMagicLen] = {};
  in.read(magic, kMagicLen);
  return in.gcount() == static_cast<std::streamsize>(kMagicLen) && std::memcmp(magic, kMagic, kMagicLen) == 0;
}

bool isHex32(std::string_view s) {
  return s.size() == 32 && std::all_of(s.begin(), s.end(), [](char c) {
           return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
         });
}

std::string seconds(Time t) { return std::to_string(static_cast<double>(t) * 1e-9); }

}  // namespace

void BagWriter::checkOutput(const std::string& path, const WriterOptions& o) {
  if (path.empty()) fail("''", o.option, "is an empty path");
  checkOutputFile(path, o.option);  // not a folder or a device, in an existing folder that can be written
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(path, ec);
  if (fs::is_symlink(st)) fail(path, o.option, "is a symbolic link, which is never replaced");
  if (fs::exists(st)) {
    if (!o.overwrite) fail(path, o.option, "already exists (" + o.replace_hint + ")");
    if (!fs::is_regular_file(st) || !startsWithBagMagic(path))
      fail(path, o.option, "is not a ROS bag: only an earlier bag is replaced");
  }
  const std::string partial = path + ".partial";
  const fs::file_status pst = fs::symlink_status(partial, ec);
  if (fs::exists(pst)) {
    const bool leftover =
        fs::is_regular_file(pst) && (fs::file_size(partial, ec) == 0 || startsWithBagMagic(partial));
    if (!leftover)
      fail(partial, o.option, "exists and is not a bag an interrupted run left: remove or rename it");
  }
}

BagWriter::BagWriter(const std::string& path, const WriterOptions& options)
    : path_(path), partial_(path + ".partial"), options_(options) {
  if (options.chunk_bytes == 0) throw std::invalid_argument("bag writer: chunk_bytes must be at least 1");
  checkOutput(path, options);
  out_.open(partial_, std::ios::binary | std::ios::trunc);
  if (!out_) fail(partial_, options_.option, std::string("cannot create file: ") + std::strerror(errno));
  try {
    put(std::string(kMagic, kMagicLen));
    writeHeaderRecord(0);  // index_pos 0 until finish(): an unindexed bag, as rosbag's while recording
  } catch (...) {
    out_.close();
    std::error_code ec;
    fs::remove(partial_, ec);
    throw;
  }
}

BagWriter::~BagWriter() {
  if (finished_) return;
  out_.close();
  std::error_code ec;
  fs::remove(partial_, ec);
}

void BagWriter::put(const std::string& bytes) {
  out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out_) fail(partial_, "", "write failed (disk full?)");
  pos_ += bytes.size();
  counts_.bytes = pos_;
}

void BagWriter::writeHeaderRecord(std::uint64_t index_pos) {
  std::string header;
  field(header, "op", op(Op::kBagHeader));
  field(header, "index_pos", packed(index_pos));
  field(header, "conn_count", packed(static_cast<std::uint32_t>(connections_.size())));
  field(header, "chunk_count", packed(static_cast<std::uint32_t>(chunks_.size())));
  std::string record;
  appendRecord(record, header, std::string(kHeaderRecordLen - header.size(), ' '));
  if (index_pos == 0) return put(record);
  out_.seekp(static_cast<std::streamoff>(kMagicLen));
  out_.write(record.data(), static_cast<std::streamsize>(record.size()));
  if (!out_) fail(partial_, "bag header", "write failed");
}

std::uint32_t BagWriter::addConnection(const std::string& topic, const ros::MessageType& type) {
  if (finished_) throw std::logic_error("bag writer: addConnection() after finish()");
  if (topic.empty()) throw std::invalid_argument("bag writer: a connection needs a topic");
  for (const ConnectionInfo& c : connections_)
    if (c.topic == topic) throw std::invalid_argument("bag writer: topic " + topic + " already has a connection");
  if (type.name.find('/') == std::string_view::npos || !isHex32(type.md5sum) || type.definition.empty())
    throw std::invalid_argument("bag writer: topic " + topic + ": message type '" + std::string(type.name) +
                                "' needs a package/Name, a 32-digit md5sum and a definition");
  connections_.push_back({topic, type, false});
  return static_cast<std::uint32_t>(connections_.size() - 1);
}

void BagWriter::appendConnectionRecord(std::string& out, std::uint32_t conn) const {
  const ConnectionInfo& c = connections_[conn];
  std::string header, data;
  field(header, "op", op(Op::kConnection));
  field(header, "conn", packed(conn));
  field(header, "topic", c.topic);
  field(data, "topic", c.topic);
  field(data, "type", c.type.name);
  field(data, "md5sum", c.type.md5sum);
  field(data, "message_definition", c.type.definition);
  appendRecord(out, header, data);
}

void BagWriter::write(std::uint32_t conn, Time record_time, std::string_view data) {
  if (finished_) throw std::logic_error("bag writer: write() after finish()");
  if (conn >= connections_.size())
    throw std::invalid_argument("bag writer: unknown connection " + std::to_string(conn));
  const std::string& topic = connections_[conn].topic;
  if (record_time < 0 || record_time >= kMaxRecordTime)
    throw std::invalid_argument("bag writer: message on " + topic + " at " + seconds(record_time) +
                                " s: ROS time holds 0 .. 2^32 s");
  if (counts_.messages > 0 && record_time < last_time_)
    throw std::invalid_argument("bag writer: message on " + topic + " at " + seconds(record_time) +
                                " s is before the previous message at " + seconds(last_time_) + " s");
  if (data.size() > kMaxChunk / 2)
    throw std::invalid_argument("bag writer: message on " + topic + " has " + std::to_string(data.size()) +
                                " bytes, more than a chunk may hold (512 MiB)");
  std::string header;
  field(header, "op", op(Op::kMessageData));
  field(header, "conn", packed(conn));
  field(header, "time", packedTime(record_time));
  const std::uint64_t record_len = 8 + header.size() + data.size();
  if (!chunk_.empty() && chunk_.size() + record_len + 65536 > kMaxChunk) flushChunk();
  if (!connections_[conn].in_file) {
    appendConnectionRecord(chunk_, conn);  // a reader scanning the chunks meets the definition first
    connections_[conn].in_file = true;
  }
  if (chunk_index_.empty()) chunk_start_ = record_time;
  chunk_end_ = record_time;
  chunk_index_[conn].push_back({record_time, static_cast<std::uint32_t>(chunk_.size())});
  appendRecord(chunk_, header, data);
  last_time_ = record_time;
  ++counts_.messages;
  if (chunk_.size() >= options_.chunk_bytes) flushChunk();
}

void BagWriter::flushChunk() {
  if (chunk_.empty()) return;
  ChunkInfo info;
  info.pos = pos_;
  info.start = chunk_start_;
  info.end = chunk_end_;
  std::string header;
  field(header, "op", op(Op::kChunk));
  field(header, "compression", "none");
  field(header, "size", packed(static_cast<std::uint32_t>(chunk_.size())));
  put(recordPrefix(header, chunk_.size()));
  put(chunk_);
  std::string index;
  for (const auto& [conn, entries] : chunk_index_) {
    std::string h, data;
    field(h, "op", op(Op::kIndexData));
    field(h, "ver", packed(std::uint32_t{1}));
    field(h, "conn", packed(conn));
    field(h, "count", packed(static_cast<std::uint32_t>(entries.size())));
    for (const IndexEntry& e : entries) data += packedTime(e.time) + packed(e.offset);
    appendRecord(index, h, data);
    info.counts[conn] = static_cast<std::uint32_t>(entries.size());
  }
  put(index);
  out_.flush();  // a process killed later leaves this chunk whole in PATH.partial
  if (!out_) fail(partial_, "", "write failed (disk full?)");
  chunks_.push_back(std::move(info));
  ++counts_.chunks;
  chunk_.clear();
  chunk_index_.clear();
}

void BagWriter::finish() {
  if (finished_) throw std::logic_error("bag writer: finish() called twice");
  flushChunk();
  const std::uint64_t index_pos = pos_;
  std::string index;
  for (std::uint32_t c = 0; c < connections_.size(); ++c) appendConnectionRecord(index, c);
  for (const ChunkInfo& info : chunks_) {
    std::string h, data;
    field(h, "op", op(Op::kChunkInfo));
    field(h, "ver", packed(std::uint32_t{1}));
    field(h, "chunk_pos", packed(info.pos));
    field(h, "start_time", packedTime(info.start));
    field(h, "end_time", packedTime(info.end));
    field(h, "count", packed(static_cast<std::uint32_t>(info.counts.size())));
    for (const auto& [conn, count] : info.counts) data += packed(conn) + packed(count);
    appendRecord(index, h, data);
  }
  put(index);
  writeHeaderRecord(index_pos);
  out_.close();
  if (!out_) fail(partial_, "", "write failed (disk full?)");
  std::error_code ec;
  fs::rename(partial_, path_, ec);  // replaces an earlier bag in one step
  if (ec) fail(path_, options_.option, "cannot rename " + partial_ + " to it: " + ec.message());
  finished_ = true;
}

}  // namespace drover::io::bag
