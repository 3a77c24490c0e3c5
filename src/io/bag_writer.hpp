#pragma once
// Writer of ROS1 bag v2.0 files (http://wiki.ros.org/Bags/Format/2.0; the reader is io/bag_format.hpp), laid out
// as rosbag writes an uncompressed bag, so that `rosbag info`, `rosbag play` and python rosbag accept it:
//
//   "#ROSBAG V2.0\n"
//   bag header record (op 0x03: index_pos, conn_count, chunk_count), padded with spaces to 4096 bytes
//   per chunk: chunk record (op 0x05, compression "none", size) holding a connection record (op 0x07) before the
//              first message of each connection and the message data records (op 0x02: conn, time), followed by
//              one index data record (op 0x04, ver 1: (time, offset into the chunk) per message) per connection
//   at index_pos: a connection record per connection, then a chunk info record (op 0x06, ver 1: chunk_pos,
//              start_time, end_time, (conn, count) pairs) per chunk
//
// Connection headers carry topic, type, md5sum and the full message_definition (io/ros_message_definitions.hpp),
// which readers without compiled message classes need. Record times must not decrease, so every per-connection
// index is sorted as rosbag's readers expect, and the messages lie in the file in time order.
//
// Interrupted writes: the bag is written as PATH.partial and renamed to PATH by finish(); a writer destroyed
// without finish() (an exception, Ctrl-C unwinding) removes PATH.partial. Until finish() its header says
// index_pos = 0, as rosbag's during recording, so even a PATH.partial left by a killed process is a valid unindexed
// bag of its complete chunks (`rosbag reindex`, Drover's reader scans it).
#include <cstdint>
#include <fstream>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "io/ros_message_definitions.hpp"
#include "types/time.hpp"

namespace drover::io::bag {

struct WriterOptions {
  // Replace an existing PATH; it must then be a ROS bag (a file starting with "#ROSBAG V2.0"), never a folder, a
  // link or another file. Without it an existing PATH is an error.
  bool overwrite = false;
  std::string replace_hint = "use --force to replace it";  // appended to "already exists"
  std::string option = "--out";  // names the path's source in errors: "[error] PATH (--out): ..."
  // [bytes] a chunk is closed once it holds this many (rosbag's default 768 KiB; larger messages make larger
  // chunks). At least 1.
  std::uint32_t chunk_bytes = 768 * 1024;
};

struct WriterCounts {
  std::size_t messages = 0, chunks = 0;
  std::uint64_t bytes = 0;  // [bytes] written to the file so far
};

class BagWriter {
 public:
  // Why PATH may not be written with these options (throws IoError(PATH, option, why)); the constructor checks
  // too. A leftover PATH.partial is replaced only when it is empty or a bag (an interrupted writer's).
  static void checkOutput(const std::string& path, const WriterOptions& options);

  // Checks, then creates PATH.partial and writes the magic line and a provisional bag header.
  explicit BagWriter(const std::string& path, const WriterOptions& options = {});
  ~BagWriter();  // without finish(): removes PATH.partial
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  // A new connection (ids 0, 1, ...); one per topic. Throws std::invalid_argument for an empty topic, a topic
  // given twice or a type without name, md5sum or definition.
  std::uint32_t addConnection(const std::string& topic, const ros::MessageType& type);

  // Appends one serialized message. record_time: the time it was recorded [ns since the Unix epoch], in
  // [0, 2^32 s) and not before the previous message's (std::invalid_argument otherwise, naming the topic).
  void write(std::uint32_t conn, Time record_time, std::string_view data);

  // Closes the last chunk, writes the index, rewrites the bag header and renames PATH.partial to PATH (replacing
  // an earlier bag). Throws IoError when the disk refuses.
  void finish();

  const WriterCounts& counts() const { return counts_; }
  const std::string& partialPath() const { return partial_; }
  const std::string& path() const { return path_; }

 private:
  struct ConnectionInfo {
    std::string topic;
    ros::MessageType type;
    bool in_file = false;  // its connection record has been written into a chunk
  };
  struct IndexEntry {
    Time time;
    std::uint32_t offset;  // [bytes] into the chunk's data
  };
  struct ChunkInfo {
    std::uint64_t pos = 0;  // file offset of the chunk record
    Time start = 0, end = 0;
    std::map<std::uint32_t, std::uint32_t> counts;  // connection -> messages in the chunk
  };

  void writeHeaderRecord(std::uint64_t index_pos);
  void appendConnectionRecord(std::string& out, std::uint32_t conn) const;
  void flushChunk();
  void put(const std::string& bytes);

  std::string path_, partial_;
  WriterOptions options_;
  std::ofstream out_;
  std::uint64_t pos_ = 0;  // [bytes] written
  std::vector<ConnectionInfo> connections_;
  std::vector<ChunkInfo> chunks_;
  std::string chunk_;  // records of the open chunk
  std::map<std::uint32_t, std::vector<IndexEntry>> chunk_index_;
  Time chunk_start_ = 0, chunk_end_ = 0, last_time_ = 0;
  WriterCounts counts_;
  bool finished_ = false;
};

}  // namespace drover::io::bag
