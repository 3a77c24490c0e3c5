// Indexing a bag whose index was never written (index_pos = 0: the recorder was killed), by a linear scan of its
// top-level records and of the records inside each chunk, as `rosbag reindex` does.
#include <cstring>
#include <unordered_set>

#include "io/bag_format.hpp"
#include "io/error.hpp"

namespace drover::io::bag {

bool BagFile::recordFits(std::uint64_t pos) {
  if (pos > size_ || size_ - pos < 8) return false;
  std::uint32_t header_len = 0, data_len = 0;
  read(pos, &header_len, 4, "record at byte " + std::to_string(pos));
  if (header_len > size_ - pos - 8) return false;
  read(pos + 4 + header_len, &data_len, 4, "record at byte " + std::to_string(pos));
  return data_len <= size_ - pos - 8 - header_len;
}

BagIndex BagFile::scanIndex(std::uint64_t pos) {
  BagIndex index;
  index.scanned = true;
  std::unordered_set<std::uint32_t> known;
  while (pos < size_) {
    if (!recordFits(pos)) break;  // the record being written when the recording stopped
    const std::string where = "record at byte " + std::to_string(pos) + " (scanning an unindexed bag)";
    auto [f, span] = readRecord(pos, where);
    switch (f.op()) {
      case Op::kChunk: {
        Chunk chunk;
        chunk.record_pos = pos;
        describeChunk(chunk, f, span, where);
        if (chunk.data_len == 0) break;  // header of a chunk the recorder never finished
        index.chunks.push_back(chunk);
        scanChunk(index, static_cast<std::uint32_t>(index.chunks.size() - 1));
        break;
      }
      case Op::kConnection: {
        const std::vector<std::uint8_t> data = readData(span, where);
        Connection c = connectionFromRecord(f, data.data(), data.size(), where);
        if (known.insert(c.id).second) index.connections.push_back(std::move(c));
        break;
      }
      case Op::kMessageData:
        // Records of a chunk still open when the recording stopped (its header says 0 bytes): the unread tail.
        index.unread_tail_bytes = size_ - pos;
        pos = size_;
        continue;
      case Op::kIndexData:
      case Op::kChunkInfo:
        break;  // index records of a partly written index: the scan rebuilds them
      default:
        fail(path_, where, "unexpected record op " + std::to_string(static_cast<int>(f.op())) + " at top level");
    }
    pos = span.end();
  }
  if (pos < size_) index.unread_tail_bytes = size_ - pos;
  // Connections met inside chunks are added by scanChunk; make the list unique (first definition wins).
  std::vector<Connection> unique;
  known.clear();
  for (Connection& c : index.connections)
    if (known.insert(c.id).second) unique.push_back(std::move(c));
  index.connections = std::move(unique);
  sortEntries(index);
  return index;
}

void BagFile::scanChunk(BagIndex& index, std::uint32_t chunk_no) {
  const std::vector<std::uint8_t>& data = chunkData(index, chunk_no);
  std::unordered_set<std::uint32_t> known;
  for (const Connection& c : index.connections) known.insert(c.id);
  std::uint64_t pos = 0;
  while (pos < data.size()) {
    const std::string where = "record at offset " + std::to_string(pos) + " of chunk " + std::to_string(chunk_no) +
                              " at byte " + std::to_string(index.chunks[chunk_no].record_pos);
    auto [f, span] = parseRecord(data.data(), data.size(), pos, path_, where);
    if (f.op() == Op::kConnection) {
      Connection c = connectionFromRecord(f, data.data() + span.data_begin, span.data_len, where);
      if (known.insert(c.id).second) index.connections.push_back(std::move(c));
    } else if (f.op() == Op::kMessageData) {
      const std::uint32_t conn = f.u32("conn");
      if (!known.count(conn)) fail(path_, where, "message on connection " + std::to_string(conn) + " before its definition");
      if (pos > UINT32_MAX) fail(path_, where, "chunk larger than 4 GiB");
      index.entries.push_back({f.time("time"), conn, chunk_no, static_cast<std::uint32_t>(pos)});
    } else {
      fail(path_, where, "unexpected record op " + std::to_string(static_cast<int>(f.op())) + " inside a chunk");
    }
    pos = span.end();
  }
}

}  // namespace drover::io::bag
