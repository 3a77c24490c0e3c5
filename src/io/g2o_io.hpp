#pragma once
// g2o 3-D pose-graph files (the format of g2o's EdgeSE3 / VertexSE3 and of the standard SLAM benchmark graphs
// such as parking-garage.g2o), read and written:
//   VERTEX_SE3:QUAT id x y z qx qy qz qw          T_world_vertex
//   EDGE_SE3:QUAT id1 id2 x y z qx qy qz qw I11 I12 .. I16 I22 .. I66
//                                                 T_id1_id2 measured, then the 21 upper-triangular entries of
//                                                 the 6x6 information row by row
//   FIX id [id ...]                               vertices held constant
// Blank lines and '#' comments are skipped. The information is kept exactly as g2o defines it: for g2o's error
// [t; qv] of the error transform Z^-1 T_1^-1 T_2 (translation, then the vector part of its unit quaternion
// with w >= 0). Converting it to Drover's [dp; dphi] error is done with the pose graph, in
// io/odometry/g2o_pose_graph.hpp. Plain data here: this file knows nothing of the backend.
//
// The reader is strict; each of these is an IoError naming the file and the line: a tag other than the three
// above, a wrong number of fields, a field that is not a finite number (ids: integers in int range), a
// quaternion whose norm differs from 1 by more than 1e-3 (io::kQuaternionTolerance, for files printed with
// ~6 digits; within it the quaternion is normalised), a duplicate vertex id, an edge or FIX naming an unknown
// vertex, an edge from a vertex to itself, an information matrix that is not positive semi-definite. A missing
// file and a file without any vertex are errors too.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

namespace drover::io {

struct G2oVertex {
  int id = 0;
  Eigen::Isometry3d T_world_vertex = Eigen::Isometry3d::Identity();
  std::size_t line = 0;  // line in the file read (0 when built in code), for later error messages
};

struct G2oEdge {
  int from = 0, to = 0;
  Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Identity();  // g2o's [t; qv]
  std::size_t line = 0;
};

struct G2oGraph {
  std::vector<G2oVertex> vertices;  // in file order
  std::vector<G2oEdge> edges;       // in file order
  std::vector<int> fixed;           // ids from FIX lines, in file order
};

// Throws IoError as described above.
G2oGraph readG2o(const std::string& path);

// Writes vertices, then FIX (one line, when any), then edges, numbers printed to read back exactly,
// quaternions normalised with w >= 0. Atomic (temporary file + rename). Throws std::invalid_argument naming the
// vertex/edge when a value is not finite, an edge or FIX names an unknown vertex, or a vertex id repeats;
// IoError when the file cannot be written.
void writeG2o(const std::string& path, const G2oGraph& graph);

}  // namespace drover::io
