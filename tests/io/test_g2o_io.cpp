#include "io/g2o_io.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "io/error.hpp"
#include "io/text_parsing.hpp"
#include "support/expect_io_error.hpp"
#include "support/shared_data.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {

using test::expectIoError;
using test::TempDir;
using test::writeText;

const char* const kVertex0 = "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\n";
const char* const kVertex1 = "VERTEX_SE3:QUAT 1 1 0 0 0 0 0.70710678 0.70710678\n";
const std::string kInfo = " 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 4 0 0 4 0 4";

std::string edge(const std::string& ids, const std::string& pose = "1 0 0 0 0 0 1", const std::string& info = kInfo) {
  return "EDGE_SE3:QUAT " + ids + " " + pose + info + "\n";
}

G2oGraph sampleGraph() {
  G2oGraph g;
  for (int k = 0; k < 4; ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(0.3 + k, Eigen::Vector3d(1, -2, 0.5 + k).normalized()).toRotationMatrix();
    T.translation() << 1234.5678901 * k, -0.000123456789, 3.0 / (k + 1);
    g.vertices.push_back(G2oVertex{10 * k - 5, T, 0});
  }
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Random();
  const Eigen::Matrix<double, 6, 6> info = A * A.transpose() / 3.0 + Eigen::Matrix<double, 6, 6>::Identity();
  for (int k = 1; k < 4; ++k) {
    const Eigen::Isometry3d T = g.vertices[k - 1].T_world_vertex.inverse() * g.vertices[k].T_world_vertex;
    g.edges.push_back(G2oEdge{g.vertices[k - 1].id, g.vertices[k].id, T, info, 0});
  }
  g.edges.push_back(G2oEdge{g.vertices[3].id, g.vertices[0].id, Eigen::Isometry3d::Identity(), info, 0});
  g.fixed = {-5, 15};
  return g;
}

TEST(G2oIo, WriteThenReadGivesTheSameGraphToTheLastBit) {
  TempDir dir;
  const G2oGraph g = sampleGraph();
  const std::string path = (dir / "graph.g2o").string();
  writeG2o(path, g);
  const G2oGraph r = readG2o(path);
  ASSERT_EQ(r.vertices.size(), g.vertices.size());
  ASSERT_EQ(r.edges.size(), g.edges.size());
  EXPECT_EQ(r.fixed, g.fixed);
  for (std::size_t i = 0; i < g.vertices.size(); ++i) {
    EXPECT_EQ(r.vertices[i].id, g.vertices[i].id);
    EXPECT_EQ(r.vertices[i].line, i + 1);
    // The quaternion's own round trip rounds; the written digits themselves read back exactly.
    EXPECT_TRUE(r.vertices[i].T_world_vertex.isApprox(g.vertices[i].T_world_vertex, 1e-14)) << i;
  }
  for (std::size_t i = 0; i < g.edges.size(); ++i) {
    EXPECT_EQ(r.edges[i].from, g.edges[i].from);
    EXPECT_EQ(r.edges[i].to, g.edges[i].to);
    EXPECT_TRUE(r.edges[i].T_from_to.isApprox(g.edges[i].T_from_to, 1e-14)) << i;
    EXPECT_EQ(r.edges[i].information, g.edges[i].information) << i;  // exactly: shortest round-trip digits
  }
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  const std::string text = readTextFile(path);
  EXPECT_NE(text.find("\nFIX -5\nFIX 15\nEDGE_SE3:QUAT -5 5 "), std::string::npos) << text;
}

TEST(G2oIo, ReadsTagsInAnyOrderWithCommentsFixLinesAndNormalisesNearUnitQuaternions) {
  TempDir dir;
  writeText(dir / "g.g2o", std::string("# a comment\n") + kVertex0 + "\n" + edge("0 1", "1 0 0 0 0 0 1.0004") +
                               "FIX 0 1\n" + kVertex1);
  const G2oGraph g = readG2o((dir / "g.g2o").string());
  ASSERT_EQ(g.vertices.size(), 2u);
  EXPECT_EQ(g.vertices[1].line, 6u);
  ASSERT_EQ(g.edges.size(), 1u);
  EXPECT_EQ(g.edges[0].line, 4u);
  EXPECT_NEAR(Eigen::Quaterniond(g.edges[0].T_from_to.linear()).norm(), 1.0, 1e-15);
  EXPECT_EQ(g.edges[0].information(3, 3), 4.0);
  EXPECT_EQ(g.edges[0].information(0, 0), 1.0);
  EXPECT_EQ((std::vector<int>{0, 1}), g.fixed);
  EXPECT_NEAR(g.vertices[1].T_world_vertex.linear()(1, 0), 1.0, 1e-7);  // 90 deg about z
}

TEST(G2oIo, ReadsTheUpperTriangleRowByRowAndMirrorsIt) {
  TempDir dir;
  writeText(dir / "g.g2o", std::string(kVertex0) + kVertex1 +
                               edge("0 1", "1 0 0 0 0 0 1", " 10 1 2 3 4 5 20 6 7 8 9 30 10 11 12 40 13 14 50 15 60"));
  const auto info = readG2o((dir / "g.g2o").string()).edges[0].information;
  EXPECT_EQ(info(0, 5), 5.0);
  EXPECT_EQ(info(5, 0), 5.0);
  EXPECT_EQ(info(1, 2), 6.0);
  EXPECT_EQ(info(4, 5), 15.0);
  EXPECT_EQ(info(5, 5), 60.0);
}

struct BadCase {
  const char* name;
  std::string text;
  std::string record;  // "line N" or "" when the whole file is at fault
  std::string what;
};

TEST(G2oIo, BadFilesAreErrorsNamingTheFileTheLineAndTheProblem) {
  const std::string v01 = std::string(kVertex0) + kVertex1;
  const BadCase cases[] = {
      {"short vertex", "VERTEX_SE3:QUAT 0 0 0 0 0 0 1\n", "line 1", "needs 9 fields"},
      {"long edge", v01 + edge("0 1", "1 0 0 0 0 0 1", kInfo + " 7"), "line 3", "needs 31 fields"},
      {"short edge", v01 + edge("0 1", "1 0 0 0 0 0 1", " 1 0 0"), "line 3", "found 13"},
      {"not a number", v01 + edge("0 1", "1 0 zero 0 0 0 1"), "line 3", "zero"},
      {"nan", "VERTEX_SE3:QUAT 0 nan 0 0 0 0 0 1\n", "line 1", "nan"},
      {"non-integer id", "VERTEX_SE3:QUAT 1.5 0 0 0 0 0 0 1\n", "line 1", "1.5"},
      {"id out of range", "VERTEX_SE3:QUAT 99999999999 0 0 0 0 0 0 1\n", "line 1", "out of range"},
      {"unknown tag", v01 + "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n", "line 3", "unknown tag 'EDGE_SE2'"},
      {"non-unit vertex quaternion", "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1.01\n", "line 1", "quaternion is not unit"},
      {"non-unit edge quaternion", v01 + edge("0 1", "1 0 0 0.1 0 0 1"), "line 3", "quaternion is not unit"},
      {"duplicate vertex", v01 + kVertex0, "line 3", "duplicate vertex id 0 (first on line 1)"},
      {"edge to unknown vertex", v01 + edge("0 7"), "line 3", "unknown vertex id 7"},
      {"edge to itself", v01 + edge("1 1"), "line 3", "joins vertex 1 to itself"},
      {"FIX of unknown vertex", v01 + "FIX 3\n", "line 3", "FIX refers to unknown vertex id 3"},
      {"FIX without id", v01 + "FIX\n", "line 3", "FIX needs at least one vertex id"},
      {"indefinite information", v01 + edge("0 1", "1 0 0 0 0 0 1", " 1 2 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1"),
       "line 3", "not positive semi-definite"},
      {"zero information", v01 + edge("0 1", "1 0 0 0 0 0 1", " 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0"),
       "line 3", "information matrix is zero"},
      {"empty file", "", "", "no VERTEX_SE3:QUAT line"},
      {"only comments", "# nothing\n\n", "", "no VERTEX_SE3:QUAT line"},
  };
  TempDir dir;
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = (dir / "bad.g2o").string();
    writeText(path, c.text);
    const std::string record = c.record.empty() ? path + ": " : path + " (" + c.record + "): ";
    expectIoError([&] { readG2o(path); }, {record, c.what});
  }
}

TEST(G2oIo, AMissingFileIsAnErrorNamingIt) {
  expectIoError([] { readG2o("/nonexistent/graph.g2o"); }, {"/nonexistent/graph.g2o", "cannot open"});
}

TEST(G2oIo, TheWriterRefusesNonFiniteValuesAndDanglingIdsAndLeavesNoFile) {
  TempDir dir;
  const std::string path = (dir / "out.g2o").string();
  G2oGraph g = sampleGraph();
  g.vertices[2].T_world_vertex.translation().y() = NAN;
  EXPECT_THROW(writeG2o(path, g), std::invalid_argument);
  g = sampleGraph();
  g.edges[1].information(2, 2) = INFINITY;
  EXPECT_THROW(writeG2o(path, g), std::invalid_argument);
  g = sampleGraph();
  g.edges[0].to = 99;
  EXPECT_THROW(writeG2o(path, g), std::invalid_argument);
  g = sampleGraph();
  g.fixed.push_back(98);
  EXPECT_THROW(writeG2o(path, g), std::invalid_argument);
  g = sampleGraph();
  g.vertices.push_back(g.vertices[0]);
  EXPECT_THROW(writeG2o(path, g), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(path));
  expectIoError([&] { writeG2o((dir / "no/such/folder/x.g2o").string(), sampleGraph()); }, {"x.g2o", "cannot create"});
}

TEST(G2oIo, ReadsTheParkingGarageBenchmarkGraph) {
  const auto path = test::sharedData("g2o/parking-garage.g2o");
  DROVER_REQUIRE_SHARED(path);
  const G2oGraph g = readG2o(path.string());
  EXPECT_EQ(g.vertices.size(), 1661u);
  EXPECT_EQ(g.edges.size(), 6275u);
  EXPECT_TRUE(g.fixed.empty());
  EXPECT_EQ(g.vertices.front().id, 0);
  EXPECT_EQ(g.edges.front().from, 0);
  EXPECT_EQ(g.edges.front().to, 1);
  EXPECT_NEAR(g.edges.front().information(3, 3), 4.00073, 1e-12);
  EXPECT_NEAR(g.edges.front().information(3, 5), 0.0691425, 1e-12);
  EXPECT_NEAR(g.edges.front().T_from_to.translation().x(), 4.15448, 1e-12);
}

}  // namespace
}  // namespace drover::io
