#include "io/ros_pointcloud.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "io/ros_messages.hpp"

namespace drover::io::ros {
namespace {

// sensor_msgs/PointField datatypes.
enum Datatype : std::uint8_t { kInt8 = 1, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::size_t datatypeSize(std::uint8_t d) {
  static constexpr std::size_t sizes[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
  return d >= 1 && d <= 8 ? sizes[d] : 0;
}

const char* datatypeName(std::uint8_t d) {
  static constexpr const char* names[] = {"?", "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32",
                                          "float64"};
  return d >= 1 && d <= 8 ? names[d] : "unknown";
}

struct Field {
  std::string name;
  std::uint32_t offset = 0;
  std::uint8_t datatype = 0;
};

// A used field: where it lies in a point and how to read it.
struct Accessor {
  std::uint32_t offset = 0;
  std::uint8_t datatype = 0;
  double read(const std::uint8_t* point) const {
    const std::uint8_t* p = point + offset;
    switch (datatype) {
      case kUint8: return *p;
      case kUint16: { std::uint16_t v; std::memcpy(&v, p, 2); return v; }
      case kUint32: { std::uint32_t v; std::memcpy(&v, p, 4); return v; }
      case kFloat32: { float v; std::memcpy(&v, p, 4); return v; }
      case kFloat64: { double v; std::memcpy(&v, p, 8); return v; }
      default: return 0;  // excluded when the accessor is made
    }
  }
};

struct Layout {
  std::vector<Field> fields;
  std::uint32_t height = 0, width = 0, point_step = 0, row_step = 0;
};

std::string fieldList(const Layout& l) {
  std::string s;
  for (const Field& f : l.fields) s += (s.empty() ? "" : ", ") + f.name + ":" + datatypeName(f.datatype);
  return s;
}

// The accessor of field `name` if present; throws when its datatype is not in `allowed`.
std::optional<Accessor> accessor(const Layout& l, const std::string& name, std::initializer_list<Datatype> allowed) {
  const auto it = std::find_if(l.fields.begin(), l.fields.end(), [&](const Field& f) { return f.name == name; });
  if (it == l.fields.end()) return std::nullopt;
  if (std::find(allowed.begin(), allowed.end(), it->datatype) == allowed.end()) {
    std::string expected;
    for (Datatype d : allowed) expected += (expected.empty() ? "" : " or ") + std::string(datatypeName(d));
    throw MessageError("point field '" + name + "' has datatype " + datatypeName(it->datatype) + ", expected " +
                       expected);
  }
  if (static_cast<std::uint64_t>(it->offset) + datatypeSize(it->datatype) > l.point_step)
    throw MessageError("point field '" + name + "' at offset " + std::to_string(it->offset) +
                       " reaches past point_step " + std::to_string(l.point_step));
  return Accessor{it->offset, it->datatype};
}

Accessor required(const Layout& l, const std::string& name) {
  auto a = accessor(l, name, {kFloat32, kFloat64});
  if (!a) throw MessageError("point cloud has no field '" + name + "' (fields: " + fieldList(l) + ")");
  return *a;
}

Layout readLayout(WireReader& in) {
  Layout l;
  l.height = in.get<std::uint32_t>();
  l.width = in.get<std::uint32_t>();
  const auto n = in.get<std::uint32_t>();
  if (n > in.remaining() / 13) throw MessageError("point field count " + std::to_string(n) + " is implausible");
  for (std::uint32_t i = 0; i < n; ++i) {
    Field f;
    f.name = in.string();
    f.offset = in.get<std::uint32_t>();
    f.datatype = in.get<std::uint8_t>();
    in.get<std::uint32_t>();  // count: > 1 only for array fields, which we do not read
    if (datatypeSize(f.datatype) == 0)
      throw MessageError("point field '" + f.name + "' has unknown datatype " + std::to_string(f.datatype));
    l.fields.push_back(std::move(f));
  }
  if (in.get<std::uint8_t>() != 0) throw MessageError("big-endian point clouds are not supported");
  l.point_step = in.get<std::uint32_t>();
  l.row_step = in.get<std::uint32_t>();
  return l;
}

}  // namespace

DecodedCloud decodePointCloud2(const std::uint8_t* data, std::size_t size) {
  WireReader in(data, size);
  DecodedCloud out;
  out.stamp = readHeader(in).stamp;
  const Layout l = readLayout(in);
  const auto data_len = in.get<std::uint32_t>();
  const std::uint8_t* points = in.take(data_len);

  const Accessor ax = required(l, "x"), ay = required(l, "y"), az = required(l, "z");
  const auto intensity = accessor(l, "intensity", {kFloat32, kFloat64, kUint8, kUint16, kUint32});
  const auto ring = accessor(l, "ring", {kUint8, kUint16});
  std::optional<Accessor> time;
  for (const char* name : {"time", "t", "timestamp"})
    if (!time) time = accessor(l, name, {kFloat32, kFloat64, kUint32});

  const std::uint64_t row_bytes = static_cast<std::uint64_t>(l.width) * l.point_step;
  if (l.width > 0 && l.height > 0) {
    if (l.point_step == 0) throw MessageError("point_step is 0");
    if (l.row_step < row_bytes)
      throw MessageError("row_step " + std::to_string(l.row_step) + " is smaller than width * point_step");
    const std::uint64_t needed = static_cast<std::uint64_t>(l.height - 1) * l.row_step + row_bytes;
    if (data_len < needed)
      throw MessageError("point data has " + std::to_string(data_len) + " bytes, shorter than the " +
                         std::to_string(needed) + " that height " + std::to_string(l.height) + " x width " +
                         std::to_string(l.width) + " x point_step " + std::to_string(l.point_step) + " need");
  }

  LidarScan& scan = out.scan;
  scan.has_ring = ring.has_value();
  scan.has_time = time.has_value();
  scan.points.reserve(static_cast<std::size_t>(l.width) * l.height);
  std::vector<Time> offsets_ns;  // per kept point, relative to the header stamp
  if (time) offsets_ns.reserve(scan.points.capacity());
  for (std::uint32_t r = 0; r < l.height; ++r) {
    const std::uint8_t* row = points + static_cast<std::uint64_t>(r) * l.row_step;
    for (std::uint32_t c = 0; c < l.width; ++c) {
      const std::uint8_t* p = row + static_cast<std::uint64_t>(c) * l.point_step;
      LidarPoint q;
      q.x = static_cast<float>(ax.read(p));
      q.y = static_cast<float>(ay.read(p));
      q.z = static_cast<float>(az.read(p));
      q.intensity = intensity ? static_cast<float>(intensity->read(p)) : 0.0f;
      q.ring = ring ? static_cast<std::uint16_t>(ring->read(p)) : 0;
      Time offset = 0;
      bool finite = std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) && std::isfinite(q.intensity);
      if (time) {
        const double v = time->read(p);
        finite = finite && std::isfinite(v);
        if (time->datatype == kUint32) {
          offset = static_cast<Time>(v);
        } else if (finite) {
          const bool absolute = time->datatype == kFloat64 && v > 1e6;
          // Bounds keep the ns conversion far from overflow; a sweep lasts well under an hour.
          if (absolute ? v > 1e10 : std::abs(v) > 3600.0)
            throw MessageError("implausible point time " + std::to_string(v) + " s");
          offset = absolute ? fromSeconds(v) - out.stamp : fromSeconds(v);
        }
      }
      if (!finite) {
        ++out.dropped_nonfinite;
        continue;
      }
      scan.points.push_back(q);
      if (time) offsets_ns.push_back(offset);
    }
  }

  scan.dropped_nonfinite = out.dropped_nonfinite;
  scan.t = scan.t_end = out.stamp;
  if (time && !offsets_ns.empty()) {
    const auto [lo, hi] = std::minmax_element(offsets_ns.begin(), offsets_ns.end());
    scan.t = out.stamp + std::min<Time>(0, *lo);
    scan.t_end = out.stamp + *hi;
    for (std::size_t i = 0; i < scan.points.size(); ++i)
      scan.points[i].time_offset = static_cast<float>(static_cast<double>(out.stamp + offsets_ns[i] - scan.t) * 1e-9);
  }
  return out;
}

}  // namespace drover::io::ros
