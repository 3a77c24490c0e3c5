// `drover graph optimize` end to end: a square the test writes (exact answer), the parking-garage benchmark
// from ../shared, and bad input (one line, exit code 2).
#include <gtest/gtest.h>

#include <string>

#include "io/g2o_io.hpp"
#include "support/cli.hpp"
#include "support/shared_data.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {

namespace fs = std::filesystem;

const std::string kInfo = " 100 0 0 0 0 0 100 0 0 0 0 100 0 0 0 400 0 0 400 0 400";

// A 2 m square: four vertices, odometry 0->1->2->3 and the loop 3->0, all exact; vertex 2 written 0.5 m off
// (x) and vertex 3 0.3 m off (y), so the optimum puts them back at (2, 2) and (0, 2) with cost 0.
std::string square() {
  return "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\n"
         "VERTEX_SE3:QUAT 1 2 0 0 0 0 0.7071067811865476 0.7071067811865476\n"
         "VERTEX_SE3:QUAT 2 2.5 2 0 0 0 1 0\n"
         "VERTEX_SE3:QUAT 3 0 2.3 0 0 0 -0.7071067811865476 0.7071067811865476\n"
         "EDGE_SE3:QUAT 0 1 2 0 0 0 0 0.7071067811865476 0.7071067811865476" + kInfo + "\n"
         "EDGE_SE3:QUAT 1 2 2 0 0 0 0 0.7071067811865476 0.7071067811865476" + kInfo + "\n"
         "EDGE_SE3:QUAT 2 3 2 0 0 0 0 0.7071067811865476 0.7071067811865476" + kInfo + "\n"
         "EDGE_SE3:QUAT 3 0 2 0 0 0 0 0.7071067811865476 0.7071067811865476" + kInfo + "\n";
}

TEST(GraphCli, OptimizeMovesTheVerticesToTheOptimumAndReportsTheFigures) {
  TempDir dir;
  writeText(dir / "in.g2o", square());
  const CliResult r = runDrover("graph optimize " + (dir / "in.g2o").string() + " " + (dir / "out.g2o").string() +
                                " --json " + (dir / "r.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "4 nodes, 4 edges")) << r.output;
  EXPECT_TRUE(contains(r.output, "initial cost")) << r.output;
  EXPECT_TRUE(contains(r.output, "iterations")) << r.output;
  const io::G2oGraph out = io::readG2o((dir / "out.g2o").string());
  ASSERT_EQ(out.vertices.size(), 4u);
  EXPECT_LT((out.vertices[2].T_world_vertex.translation() - Eigen::Vector3d(2, 2, 0)).norm(), 1e-6);
  EXPECT_LT((out.vertices[3].T_world_vertex.translation() - Eigen::Vector3d(0, 2, 0)).norm(), 1e-6);
  EXPECT_EQ(out.vertices[0].T_world_vertex.translation(), Eigen::Vector3d::Zero());  // the gauge
  EXPECT_EQ(out.edges.size(), 4u);
  const nlohmann::json j = readJson(dir / "r.json");
  for (const char* key : {"initial_cost", "final_cost", "iterations", "time_ms", "nodes", "edges", "converged"})
    EXPECT_TRUE(j.contains(key)) << key;
  // Initial: edges 1->2 and 2->3 each off by 0.5 m / 0.3 m in translation, weight 100: 0.5 * 100 * (0.25 + 0.25
  // + 0.09 + 0.09) = 34 (vertex 3's rotation is exact).
  EXPECT_NEAR(j["initial_cost"].get<double>(), 34.0, 1e-9);
  EXPECT_LT(j["final_cost"].get<double>(), 1e-12);
  EXPECT_EQ(j["nodes"], 4);
  EXPECT_EQ(j["edges"], 4);
  EXPECT_EQ(j["converged"], true);
  EXPECT_GE(j["iterations"].get<int>(), 1);
}

TEST(GraphCli, QuietPrintsNothingOnSuccess) {
  TempDir dir;
  writeText(dir / "in.g2o", square());
  const CliResult r = runDrover("graph optimize " + (dir / "in.g2o").string() + " " + (dir / "out.g2o").string() + " -q");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.output, "");
  EXPECT_TRUE(fs::exists(dir / "out.g2o"));
}

TEST(GraphCli, OptimizesTheParkingGarageAndItsOutputIsAtTheMinimum) {
  const auto garage = sharedData("g2o/parking-garage.g2o");
  DROVER_REQUIRE_SHARED(garage);
  TempDir dir;
  const CliResult r = runDrover("graph optimize " + garage.string() + " " + (dir / "out.g2o").string() +
                                " --json " + (dir / "r.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "1661 nodes, 6275 edges")) << r.output;
  const nlohmann::json j = readJson(dir / "r.json");
  EXPECT_GT(j["initial_cost"].get<double>(), 8000.0);
  EXPECT_LT(j["final_cost"].get<double>(), 0.62);
  // Read back and solved again: it starts where the first solve ended (the file keeps 17 digits).
  const CliResult again = runDrover("graph optimize " + (dir / "out.g2o").string() + " " +
                                    (dir / "out2.g2o").string() + " --json " + (dir / "r2.json").string());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  const nlohmann::json j2 = readJson(dir / "r2.json");
  EXPECT_NEAR(j2["initial_cost"].get<double>(), j["final_cost"].get<double>(), 1e-6);
}

// Bad input: exit code 2 and one line naming the file, the line and the problem.
void expectOneLineError(const std::string& args, const std::string& fragment) {
  const CliResult r = runDrover(args);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, fragment)) << r.output;
  EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << "one line: " << r.output;
}

TEST(GraphCli, BadInputIsOneLineAndExitCode2) {
  TempDir dir;
  const std::string out_path = (dir / "out.g2o").string();
  const auto optimize = [&](const std::string& in) { return "graph optimize " + (dir / in).string() + ' ' + out_path; };
  writeText(dir / "tag.g2o", square() + "VERTEX_XYZ 9 1 2 3\n");
  expectOneLineError(optimize("tag.g2o"), "(line 9): unknown tag 'VERTEX_XYZ'");
  writeText(dir / "short.g2o", "VERTEX_SE3:QUAT 0 0 0 0 0 0 1\n");
  expectOneLineError(optimize("short.g2o"), "short.g2o (line 1): VERTEX_SE3:QUAT needs 9");
  writeText(dir / "quat.g2o", "VERTEX_SE3:QUAT 0 0 0 0 0 0 0.5 0.5\n");
  expectOneLineError(optimize("quat.g2o"), "(line 1): quaternion is not unit");
  writeText(dir / "ids.g2o", square() + "EDGE_SE3:QUAT 1 12 0 0 0 0 0 0 1" + kInfo + "\n");
  expectOneLineError(optimize("ids.g2o"), "(line 9): edge 1 -> 12 refers to unknown vertex id 12");
  expectOneLineError(optimize("missing.g2o"), "missing.g2o: cannot open");
  writeText(dir / "ok.g2o", square());
  expectOneLineError("graph optimize " + (dir / "ok.g2o").string() + " " + (dir / "no/such/out.g2o").string(),
                     "does not exist");
  expectOneLineError(optimize("ok.g2o") + " --max-iterations 0",
                     "--max-iterations: '0' is out of range (expected an integer in [1, 1000000])");
  EXPECT_EQ(runDrover(optimize("ok.g2o") + " --loss tukey").exit_code, 2);
  EXPECT_FALSE(fs::exists(dir / "out.g2o"));
}

}  // namespace
}  // namespace drover::test
