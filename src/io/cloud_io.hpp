#pragma once
// Point-cloud files of the map: PCD (binary, as PCL writes it, fields x y z float32) and PLY (binary little endian,
// vertex x y z float32). Both are written atomically (temporary file + rename), so an interrupted run leaves either
// the previous file or none, never a half-written one.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace drover::io {

// Points [m] in the frame the caller names (the map files hold world-frame points).
using CloudPoints = std::vector<Eigen::Vector3f>;

// Throws IoError naming the file when it cannot be written, and when a point is not finite (record "point N").
void writePcdBinary(const std::string& path, const CloudPoints& points);
void writePlyBinary(const std::string& path, const CloudPoints& points);
// Reads a file written by writePcdBinary (binary x y z float32 only); throws IoError naming file and header line
// for anything else. For tests and tools.
CloudPoints readPcdBinary(const std::string& path);

}  // namespace drover::io
