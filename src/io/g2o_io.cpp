#include "io/g2o_io.hpp"

#include <Eigen/Eigenvalues>
#include <climits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

#include "io/error.hpp"
#include "io/text_parsing.hpp"
#include "io/trajectory_io.hpp"

namespace drover::io {

namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

constexpr std::string_view kVertexTag = "VERTEX_SE3:QUAT";
constexpr std::string_view kEdgeTag = "EDGE_SE3:QUAT";
constexpr std::string_view kFixTag = "FIX";
constexpr std::size_t kVertexFields = 1 + 1 + 7;    // tag id x y z qx qy qz qw
constexpr std::size_t kEdgeFields = 1 + 2 + 7 + 21;  // tag id1 id2 x y z qx qy qz qw + upper triangle

struct Context {
  const std::string& file;
  std::string record;
};

void requireFields(const std::vector<std::string_view>& fields, std::size_t n, const char* layout,
                   const Context& c) {
  if (fields.size() != n)
    fail(c.file, c.record,
         std::string(fields[0]) + " needs " + std::to_string(n) + " fields (" + layout + "), found " +
             std::to_string(fields.size()));
}

int parseId(std::string_view token, const Context& c) {
  const std::int64_t id = parseInt64(token, c.file, c.record);
  if (id < INT_MIN || id > INT_MAX) fail(c.file, c.record, "vertex id " + std::string(token) + " is out of range");
  return static_cast<int>(id);
}

// x y z qx qy qz qw from fields[first ...].
Eigen::Isometry3d parsePose(const std::vector<std::string_view>& fields, std::size_t first, const Context& c) {
  const std::vector<double> v = parseDoubles(fields, first, 7, c.file, c.record);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = checkedQuaternion(v[6], v[3], v[4], v[5], c.file, c.record).toRotationMatrix();
  T.translation() << v[0], v[1], v[2];
  return T;
}

// The 21 upper-triangular entries, row by row (g2o's EdgeSE3::read), mirrored; must be positive semi-definite
// and not zero (an edge that weighs nothing is a broken file, not a measurement).
Matrix6d parseInformation(const std::vector<std::string_view>& fields, std::size_t first, const Context& c) {
  const std::vector<double> v = parseDoubles(fields, first, 21, c.file, c.record);
  Matrix6d info;
  std::size_t k = 0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i; j < 6; ++j) info(i, j) = info(j, i) = v[k++];
  }
  const Eigen::Matrix<double, 6, 1> lambda = Eigen::SelfAdjointEigenSolver<Matrix6d>(info).eigenvalues();
  const double scale = lambda.cwiseAbs().maxCoeff();
  if (scale == 0) fail(c.file, c.record, "information matrix is zero");
  if (lambda.minCoeff() < -1e-9 * scale)
    fail(c.file, c.record,
         "information matrix is not positive semi-definite (eigenvalue " + formatDouble(lambda.minCoeff()) + ")");
  return info;
}

std::string joinNumbers(std::initializer_list<double> values) {
  std::string s;
  for (const double x : values) {
    s += ' ';  // appended piecewise: GCC 12 warns (-Wrestrict, a false positive) on " " + std::string
    s += formatDouble(x);
  }
  return s;
}

std::string poseText(const Eigen::Isometry3d& T) {
  Eigen::Quaterniond q = Eigen::Quaterniond(T.linear()).normalized();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d& t = T.translation();
  return joinNumbers({t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()});
}

}  // namespace

G2oGraph readG2o(const std::string& path) {
  G2oGraph graph;
  std::unordered_map<int, std::size_t> vertex_lines;
  std::vector<std::size_t> fix_lines;
  for (const NumberedLine& line : readDataLines(path)) {
    const Context c{path, lineRecord(line.number)};
    const std::vector<std::string_view> fields = splitWhitespace(line.text);
    if (fields[0] == kVertexTag) {
      requireFields(fields, kVertexFields, "id x y z qx qy qz qw", c);
      G2oVertex v{parseId(fields[1], c), parsePose(fields, 2, c), line.number};
      const auto [it, inserted] = vertex_lines.emplace(v.id, line.number);
      if (!inserted)
        fail(path, c.record,
             "duplicate vertex id " + std::to_string(v.id) + " (first on line " + std::to_string(it->second) + ")");
      graph.vertices.push_back(v);
    } else if (fields[0] == kEdgeTag) {
      requireFields(fields, kEdgeFields, "id1 id2 x y z qx qy qz qw and 21 information entries", c);
      G2oEdge e{parseId(fields[1], c), parseId(fields[2], c), parsePose(fields, 3, c), parseInformation(fields, 10, c),
                line.number};
      if (e.from == e.to) fail(path, c.record, "edge joins vertex " + std::to_string(e.from) + " to itself");
      graph.edges.push_back(e);
    } else if (fields[0] == kFixTag) {
      if (fields.size() < 2) fail(path, c.record, "FIX needs at least one vertex id");
      for (std::size_t i = 1; i < fields.size(); ++i) {
        graph.fixed.push_back(parseId(fields[i], c));
        fix_lines.push_back(line.number);
      }
    } else {
      fail(path, c.record,
           "unknown tag '" + std::string(fields[0]) + "' (a 3-D pose graph has VERTEX_SE3:QUAT, EDGE_SE3:QUAT, FIX)");
    }
  }
  if (graph.vertices.empty()) fail(path, "", "no VERTEX_SE3:QUAT line: empty or not a 3-D pose graph");
  for (const G2oEdge& e : graph.edges) {
    for (const int id : {e.from, e.to}) {
      if (!vertex_lines.count(id))
        fail(path, lineRecord(e.line), "edge " + std::to_string(e.from) + " -> " + std::to_string(e.to) +
                                           " refers to unknown vertex id " + std::to_string(id));
    }
  }
  for (std::size_t i = 0; i < graph.fixed.size(); ++i) {
    if (!vertex_lines.count(graph.fixed[i]))
      fail(path, lineRecord(fix_lines[i]), "FIX refers to unknown vertex id " + std::to_string(graph.fixed[i]));
  }
  return graph;
}

void writeG2o(const std::string& path, const G2oGraph& graph) {
  std::unordered_set<int> ids;
  std::string out;
  for (const G2oVertex& v : graph.vertices) {
    const std::string name = "writeG2o " + path + ": vertex " + std::to_string(v.id);
    if (!ids.insert(v.id).second) throw std::invalid_argument(name + " appears twice");
    if (!v.T_world_vertex.matrix().allFinite()) throw std::invalid_argument(name + " has a non-finite pose");
    out += std::string(kVertexTag) + " " + std::to_string(v.id) + poseText(v.T_world_vertex) + "\n";
  }
  for (const int id : graph.fixed) {
    if (!ids.count(id))
      throw std::invalid_argument("writeG2o " + path + ": FIX of unknown vertex " + std::to_string(id));
    out += std::string(kFixTag) + " " + std::to_string(id) + "\n";
  }
  for (const G2oEdge& e : graph.edges) {
    const std::string name = "writeG2o " + path + ": edge " + std::to_string(e.from) + " -> " + std::to_string(e.to);
    if (!ids.count(e.from) || !ids.count(e.to)) throw std::invalid_argument(name + " refers to an unknown vertex");
    if (!e.T_from_to.matrix().allFinite() || !e.information.allFinite())
      throw std::invalid_argument(name + " has a non-finite measurement or information");
    out += std::string(kEdgeTag) + " " + std::to_string(e.from) + " " + std::to_string(e.to) + poseText(e.T_from_to);
    for (int i = 0; i < 6; ++i) {
      for (int j = i; j < 6; ++j) {
        out += ' ';
        out += formatDouble(e.information(i, j));
      }
    }
    out += "\n";
  }
  writeFileAtomically(path, out);
}

}  // namespace drover::io
