// Fuzzing the single-file readers: TUM, KITTI (+ times) and EuRoC trajectories, g2o pose graphs, the shipped
// platform configs through every section loader, and PNG images. Mutated inputs must read cleanly (and sanely) or
// end in one short io::IoError naming the file -- never another exception, a crash or a hang (reader_fuzz.hpp).
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "fuzz/fixtures.hpp"
#include "fuzz/reader_fuzz.hpp"
#include "io/config.hpp"
#include "io/g2o_io.hpp"
#include "io/image_file_io.hpp"
#include "io/kitti_common.hpp"
#include "io/odometry/odometry_config_io.hpp"
#include "io/sim_dataset.hpp"
#include "io/trajectory_io.hpp"
#include "io/visual/visual_config_io.hpp"

namespace drover::test::fuzz {
namespace {

std::string checkTrajectory(const Trajectory& t) {
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!t[i].T_world_body.matrix().allFinite()) return "pose " + std::to_string(i) + " not finite";
    if (i > 0 && t[i].t <= t[i - 1].t) return "times not increasing at pose " + std::to_string(i);
  }
  return t.empty() ? "an empty trajectory returned without an error" : "";
}

TEST(FuzzTrajectories, MutatedTumKittiAndEurocFilesReadCleanlyOrFailNamingTheFile) {
  ReaderTarget t;
  t.name = "trajectories";
  t.write_fixture = [](const fs::path& root) { writeTrajectories(root); };
  t.files = {{"traj.tum"}, {"traj_kitti.txt"}, {"times.txt"}, {"traj_euroc.csv"}};
  t.read = [](const fs::path& root) {
    const std::string wrong = checkTrajectory(io::readTum((root / "traj.tum").string()));
    if (!wrong.empty()) return "TUM: " + wrong;
    const std::string k =
        checkTrajectory(io::readKitti((root / "traj_kitti.txt").string(), (root / "times.txt").string()));
    if (!k.empty()) return "KITTI: " + k;
    const std::string e = checkTrajectory(io::readEurocCsv((root / "traj_euroc.csv").string()));
    return e.empty() ? e : "EuRoC: " + e;
  };
  runCampaign(t, 400);
}

TEST(FuzzG2o, MutatedPoseGraphsReadCleanlyOrFailNamingTheFile) {
  ReaderTarget t;
  t.name = "g2o";
  t.write_fixture = [](const fs::path& root) { writeG2oGraph(root / "graph.g2o"); };
  t.files = {{"graph.g2o"}};
  t.read = [](const fs::path& root) {
    const io::G2oGraph g = io::readG2o((root / "graph.g2o").string());
    for (const auto& v : g.vertices)
      if (!v.T_world_vertex.matrix().allFinite()) return std::string("vertex not finite");
    for (const auto& e : g.edges)
      if (!e.T_from_to.matrix().allFinite() || !e.information.allFinite()) return std::string("edge not finite");
    return std::string();
  };
  runCampaign(t, 400);
}

class FuzzConfig : public ::testing::TestWithParam<const char*> {};

TEST_P(FuzzConfig, MutatedPlatformConfigsLoadOrFailNamingTheFile) {
  ReaderTarget t;
  const std::string name = GetParam();
  t.name = "config " + name;
  t.write_fixture = [name](const fs::path& root) {
    fs::create_directories(root);
    fs::copy_file(fs::path(DROVER_SOURCE_DIR) / "config" / name, root / name);
  };
  t.files = {{name}};
  t.read = [name](const fs::path& root) {
    const std::string path = (root / name).string();
    io::loadDatasetOptions(path);
    io::loadOdometryConfig(path);
    io::loadVisualConfig(path);
    io::loadSimConfigSettings(path);
    return std::string();
  };
  runCampaign(t, 150);
}

INSTANTIATE_TEST_SUITE_P(Shipped, FuzzConfig,
                         ::testing::Values("kitti.yaml", "kitti_raw.yaml", "euroc.yaml", "m2dgr.yaml", "lvisam.yaml",
                                           "farm_sim.yaml"),
                         [](const auto& info) {
                           std::string s = info.param;
                           return s.substr(0, s.find('.'));
                         });

// A PNG whose IHDR claims width x height, with a correct CRC so that only the size is wrong.
std::string pngClaiming(std::string png, std::uint32_t width, std::uint32_t height) {
  for (int i = 0; i < 4; ++i) {
    png[16 + i] = static_cast<char>(width >> (24 - 8 * i));
    png[20 + i] = static_cast<char>(height >> (24 - 8 * i));
  }
  const std::uint32_t crc =
      png_detail::crc32(reinterpret_cast<const std::uint8_t*>(png.data() + 12), 17);  // type + 13 data bytes
  for (int i = 0; i < 4; ++i) png[29 + i] = static_cast<char>(crc >> (24 - 8 * i));
  return png;
}

TEST(FuzzPng, MutatedImagesDecodeOrFailNamingTheFile) {
  ReaderTarget t;
  t.name = "png";
  t.write_fixture = [](const fs::path& root) {
    writeTexturedPng(root / "grey.png", 32, 24, 1);
    writeTexturedPng(root / "colour.png", 16, 8, 3);
  };
  t.files = {{"grey.png", true, 1}, {"colour.png", true, 1}};
  t.read = [](const fs::path& root) {
    for (const char* f : {"grey.png", "colour.png"}) {
      const Image im = io::readImageFile((root / f).string());
      if (im.data.size() != static_cast<std::size_t>(im.width) * im.height * im.channels || im.data.empty())
        return std::string(f) + ": image buffer does not match its size";
      const cv::Mat grey = io::readGreyImage((root / f).string());
      if (grey.empty() || grey.type() != CV_8UC1) return std::string(f) + ": grey image empty or not 8-bit";
    }
    return std::string();
  };
  TempDir scratch;
  writeTexturedPng(scratch / "grey.png", 32, 24, 1);
  const std::string grey = readText(scratch / "grey.png");
  // Item 11 of issue 14: a header claiming 100000 x 100000 px must give an IoError, not OpenCV's assertion.
  t.extra.push_back(
      {"grey.png", {"IHDR claims 100000 x 100000", pngClaiming(grey, 100000, 100000)}, "grey.png", "Assertion"});
  t.extra.push_back({"grey.png", {"IHDR claims 0 x 24", pngClaiming(grey, 0, 24)}, "grey.png"});
  t.extra.push_back({"grey.png", {"IHDR claims 2^31 x 1", pngClaiming(grey, 0x80000000u, 1)}, "grey.png"});
  runCampaign(t, 300);
}

}  // namespace
}  // namespace drover::test::fuzz
