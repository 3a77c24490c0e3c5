#include "io/cloud_io.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

#include "io/error.hpp"
#include "io/trajectory_io.hpp"

namespace drover::io {
namespace {

static_assert(sizeof(float) == 4, "PCD/PLY float32");

void checkFinite(const std::string& path, const CloudPoints& points) {
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite()) fail(path, "point " + std::to_string(i), "not finite; refusing to write it");
}

// x y z of every point as little-endian float32 (x86 and ARM Linux are little endian).
std::string packedXyz(const CloudPoints& points) {
  std::string bytes(points.size() * 12, '\0');
  for (std::size_t i = 0; i < points.size(); ++i) std::memcpy(&bytes[i * 12], points[i].data(), 12);
  return bytes;
}

}  // namespace

void writePcdBinary(const std::string& path, const CloudPoints& points) {
  checkFinite(path, points);
  std::ostringstream h;
  h << "# .PCD v0.7 - Point Cloud Data file format (written by Drover)\n"
    << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
    << "WIDTH " << points.size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << points.size()
    << "\nDATA binary\n";
  writeFileAtomically(path, h.str() + packedXyz(points));
}

void writePlyBinary(const std::string& path, const CloudPoints& points) {
  checkFinite(path, points);
  std::ostringstream h;
  h << "ply\nformat binary_little_endian 1.0\ncomment written by Drover\nelement vertex " << points.size()
    << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  writeFileAtomically(path, h.str() + packedXyz(points));
}

CloudPoints readPcdBinary(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "", "cannot open");
  std::string line;
  std::size_t n = 0;
  int line_no = 0;
  bool data = false;
  while (!data && std::getline(in, line)) {
    ++line_no;
    const std::string rec = "header line " + std::to_string(line_no);
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    if (key == "FIELDS" && line != "FIELDS x y z") fail(path, rec, "expected FIELDS x y z, got '" + line + "'");
    if (key == "TYPE" && line != "TYPE F F F") fail(path, rec, "expected float32 fields, got '" + line + "'");
    if (key == "POINTS" && !(ls >> n)) fail(path, rec, "bad POINTS count");
    if (key == "DATA") {
      if (line != "DATA binary") fail(path, rec, "only DATA binary is read, got '" + line + "'");
      data = true;
    }
  }
  if (!data) fail(path, "header", "no DATA line");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() != n * 12)
    fail(path, "data", "expected " + std::to_string(n * 12) + " bytes for " + std::to_string(n) + " points, found " +
                           std::to_string(bytes.size()));
  CloudPoints points(n);
  for (std::size_t i = 0; i < n; ++i) std::memcpy(points[i].data(), &bytes[i * 12], 12);
  return points;
}

}  // namespace drover::io
