#pragma once
// The inputs of the CLI fuzz tables, each written when a case first needs it: {kitti} (a 6-frame KITTI odometry
// sequence in a box-shaped hall), {kittiraw}, {euroc}, {sim} (a 2 s `drover sim` straight course), {bag} + {bagcfg},
// {traj} (trajectory files), {g2o}, {png}, {bigpng} (a header claiming 100000 x 100000 px), {bin} (scans for loop
// pair), {cfg} (the shipped configs), {weights} (SuperPoint's, from ../shared) and {plain} (a folder that is no
// dataset); {g2odir}, {pngdir} and {bagdir} are the folders of the single-file fixtures. Also mutatedCopy(): a copy of
// a fixture with one file mutated, for the tables of mutated inputs.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <string>

#include "fuzz/cli_fuzz.hpp"
#include "fuzz/fixtures.hpp"
#include "fuzz/mutate.hpp"
#include "io/fixtures/bag_fixtures.hpp"
#include "support/shared_data.hpp"

namespace drover::test::fuzz {

class CliFixtures {
 public:
  static CliFixtures& get() {
    static CliFixtures instance;
    return instance;
  }
  // The placeholders with their paths. A fixture is written when a case first needs it (ensureFor), because ctest
  // runs every test in its own process and most tests need only a few of them.
  const std::map<std::string, std::string>& vars() const { return vars_; }
  std::string var(const std::string& key) {
    ensure(key);
    return vars_.at(key);
  }
  const fs::path& scratch() const { return scratch_; }

  // Writes every fixture that `text` names with a {placeholder}; "" when all are ready, else what failed.
  std::string ensureFor(const std::string& text) {
    std::string failed;
    for (const auto& [key, path] : vars_)
      if (text.find(key) != std::string::npos) failed += ensure(key);
    return failed;
  }

  // A copy of fixture folder `from` with file `rel` mutated by case k of `seed`. Returns the copy's path;
  // `description` says what was done.
  fs::path mutatedCopy(const fs::path& from, const std::string& rel, bool binary, std::size_t record,
                       std::uint64_t seed, std::size_t k, std::string* description) {
    const fs::path to = dir_.path() / "mutated" / (std::to_string(copies_++) + "_" + from.filename().string());
    fs::create_directories(to.parent_path());
    fs::copy(from, to, fs::copy_options::recursive);
    Rng rng(seed * 1'000'003ull + k);
    const std::string original = readText(to / rel);
    const Mutation m = binary ? mutateBinary(original, rng, record) : mutateText(original, rng);
    std::ofstream(to / rel, std::ios::binary | std::ios::trunc) << m.bytes;
    if (description) *description = rel + ": " + m.description;
    return to;
  }

 private:
  CliFixtures() : scratch_(dir_.path() / "scratch") {
    const fs::path d = dir_.path();
    vars_ = {{"{kitti}", (d / "kitti" / "00").string()},
             {"{kittiraw}", (d / "kittiraw" / "2011_09_30_drive_0018_sync").string()},
             {"{euroc}", (d / "euroc").string()},
             {"{sim}", (d / "sim").string()},
             {"{traj}", (d / "traj").string()},
             {"{g2o}", (d / "g2o" / "graph.g2o").string()},
             {"{g2odir}", (d / "g2o").string()},
             {"{png}", (d / "png" / "board.png").string()},
             {"{pngdir}", (d / "png").string()},
             {"{bigpng}", (d / "png" / "big.png").string()},
             {"{bin}", (d / "bin").string()},
             {"{bag}", (d / "bag" / "fixture_lz4.bag").string()},
             {"{bagdir}", (d / "bag").string()},
             {"{bagcfg}", (d / "bag" / "topics.yaml").string()},
             {"{plain}", (d / "plain").string()},
             {"{cfg}", std::string(DROVER_SOURCE_DIR) + "/config"},
             {"{weights}", (sharedDir() / "models" / "superpoint_v1.onnx").string()}};
    fs::create_directories(scratch_);
  }

  // Writes fixture `key` once; "" on success, else what failed.
  std::string ensure(const std::string& key) {
    if (done_.count(key)) return done_[key];
    std::string& failed = done_[key];
    const fs::path d = dir_.path();
    if (key == "{kitti}") {
      writeKittiSequence(d / "kitti" / "00", 6, 64, 360);
    } else if (key == "{kittiraw}") {
      writeKittiRawDrive(d / "kittiraw" / "2011_09_30_drive_0018_sync");
    } else if (key == "{euroc}") {
      writeEurocSequence(d / "euroc");
    } else if (key == "{traj}") {
      writeTrajectories(d / "traj");
      std::string still;  // a degenerate trajectory: every pose at the same place
      for (int i = 0; i < 10; ++i) still += numbers({0.1 * i, 1, 2, 3, 0, 0, 0, 1}) + "\n";
      writeText(d / "traj" / "still.tum", still);
    } else if (key == "{g2o}" || key == "{g2odir}") {
      writeG2oGraph(d / "g2o" / "graph.g2o");
    } else if (key == "{png}" || key == "{pngdir}" || key == "{bigpng}") {
      writeTexturedPng(d / "png" / "board.png", 96, 64, 1);
      std::string big = readText(d / "png" / "board.png");  // the header claims 100000 x 100000 px, CRC correct
      for (int i = 0; i < 4; ++i) big[16 + i] = big[20 + i] = static_cast<char>(100000u >> (24 - 8 * i));
      const std::uint32_t crc = png_detail::crc32(reinterpret_cast<const std::uint8_t*>(big.data() + 12), 17);
      for (int i = 0; i < 4; ++i) big[29 + i] = static_cast<char>(crc >> (24 - 8 * i));
      writeText(d / "png" / "big.png", big);
    } else if (key == "{bin}") {
      writeBin(d / "bin" / "a.bin", hallScan(0, 64, 360));
      writeBin(d / "bin" / "b.bin", hallScan(0.5, 64, 360));
      writeText(d / "bin" / "empty.bin", "");
      writeText(d / "bin" / "odd.bin", std::string(15, '\1'));
      auto nan_scan = hallScan(1.0, 64, 360);
      nan_scan[10][0] = std::numeric_limits<float>::quiet_NaN();
      nan_scan[20][2] = std::numeric_limits<float>::infinity();
      writeBin(d / "bin" / "nan.bin", nan_scan);
    } else if (key == "{plain}") {
      writeText(d / "plain" / "keep.txt", "not a dataset\n");
    } else if (key == "{bag}" || key == "{bagdir}" || key == "{bagcfg}") {
      try {
        runBagWriter(d / "bag");
      } catch (const std::exception& e) {
        failed = e.what();
      }
      writeText(d / "bag" / "topics.yaml",
                "dataset:\n  lidar_topic: /velodyne_points\n  imu_topic: /imu_raw\n  image_topic: /cam/png\n");
    } else if (key == "{sim}") {
      const CliRun sim =
          runCli("sim -q --scenario straight --duration 2 --camera-rate 5 --out " + vars_.at("{sim}"), 120);
      if (sim.exit_code != 0) failed = "drover sim failed: " + sim.output;
    }
    return failed;
  }

  TempDir dir_;
  fs::path scratch_;
  std::map<std::string, std::string> vars_;
  std::map<std::string, std::string> done_;  // fixture -> "" or what failed
  std::size_t copies_ = 0;
};

}  // namespace drover::test::fuzz
