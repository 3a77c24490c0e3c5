// CLI contract fuzzing, mutated inputs: every command on copies of its fixtures with one file mutated (mutate.hpp:
// truncations, byte flips, NaN/inf/huge numbers, duplicated/removed/swapped lines). Each case must exit 0 with
// complete outputs, or exit 2 with one [error] line naming a file of the mutated copy (cli_fuzz.hpp). A row of the
// table below is a command, the fixture it mutates, the file and how many cases to draw.
#include <gtest/gtest.h>

#include "fuzz/cli_fixtures.hpp"

namespace drover::test::fuzz {
namespace {

struct MutatedInput {
  std::string command;  // {ds} = the mutated copy of `fixture`
  std::string fixture;  // a folder placeholder, e.g. "{kitti}"
  std::string file;     // relative to the fixture
  bool binary = false;
  std::size_t record = 1;
  std::size_t cases = 4;
  std::vector<std::string> outputs;  // written on success
};

void runMutated(const std::string& what, const std::vector<MutatedInput>& rows) {
  CliFixtures& f = CliFixtures::get();
  std::string all;
  for (const MutatedInput& row : rows) all += row.command + " " + row.fixture + " ";
  ASSERT_EQ(f.ensureFor(all), "") << "a fixture could not be written";
  std::vector<CliCase> cases;
  std::vector<std::string> descriptions;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const MutatedInput& row = rows[r];
    const fs::path from = expand(row.fixture, f.vars());
    for (std::size_t k = 0; k < row.cases; ++k) {
      std::string description;
      const fs::path copy = f.mutatedCopy(from, row.file, row.binary, row.record, 1000 + r, k, &description);
      std::map<std::string, std::string> ds = {{"{ds}", copy.string()}};
      CliCase c{expand(row.command, ds), Expect::kEither, copy.string(), row.outputs, 60};
      cases.push_back(c);
    }
  }
  runCliTable(what, cases, f.vars(), f.scratch());
}

TEST(FuzzCliInputs, KittiOdometry) {
  const std::string info = "info {ds} --format kitti --json {out}/i.json";
  const std::string run = "run {ds} --format kitti --config {cfg}/kitti.yaml -q --max-frames 3 --out {out}/r";
  const std::vector<std::string> r = {"{out}/r/report.json", "{out}/r/trajectory_kitti.txt"};
  runMutated("kitti", {
                          {info, "{kitti}", "times.txt", false, 1, 2, {"{out}/i.json"}},
                          {info, "{kitti}", "calib.txt", false, 1, 3, {"{out}/i.json"}},
                          {info, "{kitti}", "poses.txt", false, 1, 1, {"{out}/i.json"}},
                          {info, "{kitti}", "velodyne/000001.bin", true, 16, 2, {"{out}/i.json"}},
                          {info, "{kitti}", "image_2/000002.png", true, 1, 1, {"{out}/i.json"}},
                          {run, "{kitti}", "velodyne/000001.bin", true, 16, 2, r},
                          {run, "{kitti}", "times.txt", false, 1, 1, r},
                      });
}

TEST(FuzzCliInputs, KittiRawEurocAndBag) {
  runMutated("raw_euroc_bag", {
                                  {"info {ds} --format kitti-raw --json {out}/i.json",
                                   "{kittiraw}",
                                   "oxts/data/0000000004.txt",
                                   false,
                                   1,
                                   1,
                                   {"{out}/i.json"}},
                                  {"info {ds} --format kitti-raw --json {out}/i.json",
                                   "{kittiraw}",
                                   "velodyne_points/timestamps_start.txt",
                                   false,
                                   1,
                                   1,
                                   {"{out}/i.json"}},
                                  {"info {ds} --format euroc --json {out}/i.json",
                                   "{euroc}",
                                   "mav0/imu0/data.csv",
                                   false,
                                   1,
                                   2,
                                   {"{out}/i.json"}},
                                  {"info {ds} --format euroc --json {out}/i.json",
                                   "{euroc}",
                                   "mav0/cam0/sensor.yaml",
                                   false,
                                   1,
                                   2,
                                   {"{out}/i.json"}},
                                  {"features track -q {ds} --format euroc --detector orb --out {out}/t",
                                   "{euroc}",
                                   "mav0/cam0/data.csv",
                                   false,
                                   1,
                                   2,
                                   {"{out}/t/tracks.json"}},
                                  {"info {ds}/fixture_lz4.bag --format bag --config {bagcfg} --json {out}/i.json",
                                   "{bagdir}",
                                   "fixture_lz4.bag",
                                   true,
                                   4,
                                   3,
                                   {"{out}/i.json"}},
                              });
}

TEST(FuzzCliInputs, Sim) {
  const std::string info = "info {ds} --format sim --json {out}/i.json";
  const std::string run = "run {ds} --format sim --config {cfg}/farm_sim.yaml -q --duration 1 --out {out}/r";
  const std::vector<std::string> r = {"{out}/r/report.json", "{out}/r/trajectory.tum"};
  runMutated("sim", {
                        {info, "{sim}", "imu.csv", false, 1, 1, {"{out}/i.json"}},
                        {info, "{sim}", "lidar/timestamps.csv", false, 1, 1, {"{out}/i.json"}},
                        {info, "{sim}", "calibration.yaml", false, 1, 1, {"{out}/i.json"}},
                        {info, "{sim}", "lidar/000003.bin", true, 24, 1, {"{out}/i.json"}},
                        {run, "{sim}", "lidar/000004.bin", true, 24, 1, r},
                        {run, "{sim}", "imu.csv", false, 1, 1, r},
                    });
}

TEST(FuzzCliInputs, FilesOfEvalGraphLoopAndFeatures) {
  runMutated(
      "files",
      {
          {"eval ape {ds}/traj.tum {traj}/traj.tum --align se3 --json {out}/e.json",
           "{traj}",
           "traj.tum",
           false,
           1,
           3,
           {"{out}/e.json"}},
          {"eval rpe {ds}/traj_kitti.txt {traj}/traj_kitti.txt --format kitti --delta 2 --json {out}/e.json",
           "{traj}",
           "traj_kitti.txt",
           false,
           1,
           3,
           {"{out}/e.json"}},
          {"eval kitti {traj}/traj_kitti.txt {ds}/traj_kitti.txt --json {out}/e.json",
           "{traj}",
           "traj_kitti.txt",
           false,
           1,
           2,
           {"{out}/e.json"}},
          {"graph optimize -q {ds}/graph.g2o {out}/o.g2o --json {out}/o.json",
           "{g2odir}",
           "graph.g2o",
           false,
           1,
           3,
           {"{out}/o.g2o", "{out}/o.json"}},
          {"features detect --detector orb {ds}/board.png --json {out}/d.json",
           "{pngdir}",
           "board.png",
           true,
           1,
           2,
           {"{out}/d.json"}},
          {"loop pair -q {ds}/a.bin {bin}/b.bin --json {out}/p.json", "{bin}", "a.bin", true, 16, 2, {"{out}/p.json"}},
      });
}

TEST(FuzzCliInputs, PlatformConfigs) {
  runMutated("configs", {
                            {"info {kitti} --format kitti --config {ds}/kitti.yaml --json {out}/i.json",
                             "{cfg}",
                             "kitti.yaml",
                             false,
                             1,
                             3,
                             {"{out}/i.json"}},
                            {"run {kitti} --format kitti --config {ds}/kitti.yaml -q --max-frames 2 --out {out}/r",
                             "{cfg}",
                             "kitti.yaml",
                             false,
                             1,
                             2,
                             {"{out}/r/report.json"}},
                            {"features detect --config {ds}/euroc.yaml --detector orb {png} --json {out}/d.json",
                             "{cfg}",
                             "euroc.yaml",
                             false,
                             1,
                             2,
                             {"{out}/d.json"}},
                        });
}

}  // namespace
}  // namespace drover::test::fuzz
