// CLI contract fuzzing, out-of-range and malformed options: for every command, NaN, inf, negative, zero, huge and
// 2^70 values, empty strings, outputs that are folders or lie under a file, configs that are folders. Each row is
// one case (cli_fuzz.hpp): exit 0 with complete outputs, or exit 2 with one [error] line naming the option or file.
// Add a case by adding a line.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>

#include "fuzz/cli_fixtures.hpp"

namespace drover::test::fuzz {
namespace {

constexpr Expect kError = Expect::kError, kOk = Expect::kOk;
const std::string k2to70 = "1180591620717411303424";

void runTable(const std::string& what, std::vector<CliCase> cases) {
  CliFixtures& f = CliFixtures::get();
  if (!fs::exists(f.vars().at("{weights}"))) {  // without ../shared the weights' error would hide the option's
    const auto needs = [](const CliCase& c) { return c.args.find("{weights}") != std::string::npos; };
    const auto n = std::count_if(cases.begin(), cases.end(), needs);
    cases.erase(std::remove_if(cases.begin(), cases.end(), needs), cases.end());
    if (n > 0) std::cout << "[fuzz] " << n << " cases skipped: no " << f.vars().at("{weights}") << "\n";
  }
  std::string all;
  for (const CliCase& c : cases) all += c.args + " ";
  ASSERT_EQ(f.ensureFor(all), "") << "a fixture could not be written";
  runCliTable(what, cases, f.vars(), f.scratch());
}

TEST(FuzzCliOptions, Info) {
  const std::string kitti = "info {kitti} --format kitti ";
  runTable("info",
           {
               {kitti + "--json {out}/i.json --export-gt {out}/gt.tum", kOk, "", {"{out}/i.json", "{out}/gt.tum"}},
               {"info {kittiraw} --format kitti-raw --json {out}/i.json", kOk, "", {"{out}/i.json"}},
               {"info {euroc} --format euroc --json {out}/i.json", kOk, "", {"{out}/i.json"}},
               {"info {bag} --format bag --config {bagcfg} --json {out}/i.json", kOk, "", {"{out}/i.json"}},
               {kitti + "--max-frames -1 --json {out}/i.json", kError, "--max-frames", {"{out}/i.json"}},
               {kitti + "--max-frames " + k2to70, kError, "--max-frames"},
               {kitti + "--max-frames nan", kError, "--max-frames"},
               {kitti + "--max-frames ''", kError, "--max-frames"},
               {kitti + "--config {kitti}", kError, "{kitti}"},                // item 8: a folder as the config
               {kitti + "--json {kitti}/calib.txt/i.json", kError, "i.json"},  // item 7: output under a file
               {kitti + "--json {out}", kError, "{out}"},                      // item 7: output is a folder
               {"info {kitti} --format bag", kError, "{kitti}"},               // item 11: a folder read as a bag
           });
}

TEST(FuzzCliOptions, Sim) {
  const std::string sim = "sim -q --scenario straight --no-camera --out {out}/ds ";
  const std::vector<std::string> ds = {"{out}/ds/scenario.json"};
  std::vector<CliCase> cases = {
      {sim + "--duration 0.3", kOk, "", ds},
      {sim + "--duration 0.3 --seed -1", kError, "--seed", ds},  // item 10: became 2^64 - 1
      {sim + "--duration 0.3 --seed " + k2to70, kError, "--seed", ds},
      {sim + "--duration 0.3 --seed nan", kError, "--seed", ds},
      {sim + "--duration nan", kError, "--duration", ds},
      {sim + "--duration -1", kError, "--duration", ds},
      {sim + "--duration 1e9", kError, "--duration", ds, 5},  // item 10: must refuse up front, not fill memory
      {sim + "--duration 1e12", kError, "--duration", ds, 5},
      {sim + "--duration ''", kError, "--duration", ds},
      {"sim -q --scenario straight --duration 0.3 --camera-rate 0 --out {out}/ds", kError, "--camera-rate", ds},
      {"sim -q --scenario straight --duration 0.3 --camera-rate nan --out {out}/ds", kError, "--camera-rate", ds},
      {"sim -q --scenario straight --duration 0.3 --camera-rate 1e9 --out {out}/ds", kError, "--camera-rate", ds, 5},
      {"sim -q --scenario nowhere --duration 0.3 --out {out}/ds", kError, "--scenario", ds},
      {sim + "--duration 0.3 --config {kitti}", kError, "{kitti}", ds},  // item 8
      {"sim -q --scenario straight --duration 0.3 --no-camera --out ''", kError, "--out"},
      {"sim -q --scenario straight --duration 0.3 --no-camera --out {out}", kError, "{out}"},  // exists, no --force
      {"sim -q --scenario straight --duration 0.3 --no-camera --out {kitti}/times.txt", kError, "times.txt"},
      {"sim -q --scenario straight --duration 0.3 --no-camera --force --out {plain}", kError, "{plain}"},  // item 1
      // --format bag: --out is a file; --force replaces only a ROS bag, never a folder or another file.
      {"sim -q --scenario straight --duration 0.3 --no-camera --format bag --out {out}/s.bag", kOk, "",
       {"{out}/s.bag"}},
      {"sim -q --scenario straight --duration 0.3 --no-camera --format bag --out ''", kError, "--out"},
      {"sim -q --scenario straight --duration 0.3 --no-camera --format bag --force --out {out}", kError, "{out}"},
      {"sim -q --scenario straight --duration 0.3 --no-camera --format bag --force --out {kitti}/times.txt", kError,
       "times.txt"},
      {"sim -q --scenario straight --duration 0.3 --no-camera --format bag --out {kitti}/times.txt/s.bag", kError,
       "s.bag"},
      {"sim -q --scenario kitti05-replay --duration 0.3 --no-camera --kitti-poses {out}/none.txt --kitti-times "
       "{traj}/times.txt --out {out}/ds",
       kError, "none.txt", ds},
  };
  runTable("sim", cases);
  // Item 1: whatever happened above, --force never deleted a folder that is no dataset.
  EXPECT_TRUE(fs::exists(fs::path(CliFixtures::get().var("{plain}")) / "keep.txt"));
}

TEST(FuzzCliOptions, Run) {
  const std::string run = "run {kitti} --format kitti --config {cfg}/kitti.yaml -q --out {out}/r ";
  const std::vector<std::string> r = {"{out}/r/report.json", "{out}/r/trajectory.tum", "{out}/r/trajectory_kitti.txt"};
  runTable("run",
           {
               {run + "--max-frames 3", kOk, "", r},
               {"run {sim} --format sim --config {cfg}/farm_sim.yaml -q --duration 1.5 --out {out}/r",
                kOk,
                "",
                {"{out}/r/report.json", "{out}/r/trajectory.tum"}},
               {run + "--start nan", kError, "--start", r},
               {run + "--start -1", kError, "--start", r},
               {run + "--duration nan", kError, "--duration", r},
               {run + "--duration 1e300 --max-frames 2", kError, "--duration", r},
               {run + "--max-frames -1", kError, "--max-frames", r},
               {run + "--max-frames " + k2to70, kError, "--max-frames", r},
               {run + "--start ''", kError, "--start", r},
               {"run {kitti} --format kitti -q --out ''", kError, "--out"},
               {"run {kitti} --format kitti -q --max-frames 2 --out {kitti}/times.txt", kError, "times.txt"},  // item 7
               {"run {kitti} --format kitti -q --max-frames 2 --config {kitti} --out {out}/r", kError, "{kitti}", r},
               {"run {kitti} --format sim -q --out {out}/r", kError, "{kitti}", r},
               {"run {euroc} --format euroc -q --out {out}/r", kError, "{euroc}", r},  // no lidar sweeps
               {"run {bag} --format bag --config {bagcfg} -q --out {out}/r", Expect::kEither, "{bag}", r},
           });
}

TEST(FuzzCliOptions, Eval) {
  const std::string ape = "eval ape {traj}/traj.tum {traj}/traj.tum --json {out}/e.json ";
  const std::string rpe = "eval rpe {traj}/traj.tum {traj}/traj.tum --json {out}/e.json ";
  const std::vector<std::string> j = {"{out}/e.json"};
  runTable("eval",
           {
               {ape + "--align se3", kOk, "", j},
               {rpe + "--delta 2 --delta-unit frames", kOk, "", j},
               {"eval ape {traj}/traj_euroc.csv {traj}/traj_euroc.csv --format euroc --json {out}/e.json", kOk, "", j},
               {ape + "--t-offset 1e10", kError, "--t-offset", j},  // item 4: overflowed to 0
               {ape + "--t-offset nan", kError, "--t-offset", j},
               {ape + "--t-max-diff 1e10", kError, "--t-max-diff", j},
               {ape + "--t-max-diff nan", kError, "--t-max-diff", j},
               {ape + "--t-max-diff -1", kError, "--t-max-diff", j},
               {ape + "--t-max-diff ''", kError, "--t-max-diff", j},
               {ape + "--align affine", kError, "--align", j},
               {rpe + "--delta 0", kError, "--delta", j},
               {rpe + "--delta nan", kError, "--delta", j},
               {rpe + "--delta " + k2to70, kError, "--delta", j},
               {"eval ape {traj}/traj.tum {traj}/traj.tum --json {out}", kError, "{out}"},  // item 7
               {"eval ape {traj}/traj.tum {traj}/traj.tum --plot {out}/no/dir/p.png --json {out}/e.json", kError,
                "p.png", j},
               {"eval ape {traj}/traj.tum {traj}/still.tum --align se3 --json {out}/e.json", kError, "still.tum",
                j},  // item 11
               {"eval ape {traj}/traj.tum {out}/none.tum", kError, "none.tum"},
               {"eval ape {traj}/traj.tum {traj}/traj.tum --format kitti", kError, "traj.tum"},
               {"eval ape {traj}/traj_kitti.txt {traj}/traj_kitti.txt --format kitti --ref-times {traj}/traj.tum",
                kError, "traj.tum"},
           });
}

TEST(FuzzCliOptions, Loop) {
  const std::string pair = "loop pair -q {bin}/a.bin {bin}/b.bin ";
  const std::string eval = "loop eval -q {kitti} --format kitti --config {cfg}/kitti.yaml --json {out}/l.json ";
  const std::vector<std::string> p = {"{out}/p.json"}, l = {"{out}/l.json"};
  runTable(
      "loop",
      {
          {pair + "--json {out}/p.json", kOk, "", p},
          {"loop pair -q {bin}/a.bin {bin}/empty.bin --json {out}/p.json", kError, "empty.bin", p},  // item 11
          {"loop pair -q {bin}/a.bin {bin}/odd.bin --json {out}/p.json", kError, "odd.bin", p},
          {"loop pair -q {bin}/a.bin {bin}/nan.bin --json {out}/p.json", kOk, "nan.bin", p},  // item 9: NaN is dropped
          {pair + "--config {kitti}", kError, "{kitti}"},                                     // item 8
          {pair + "--json {out}", kError, "{out}"},                                           // item 7
          {eval, kOk, "", l},
          {eval + "--threshold nan", kError, "--threshold", l},  // item 10
          {eval + "--threshold -1", kError, "--threshold", l},
          {eval + "--keyframe-distance 0", kError, "--keyframe-distance", l},
          {eval + "--keyframe-distance nan", kError, "--keyframe-distance", l},
          {eval + "--true-distance nan", kError, "--true-distance", l},
          {eval + "--max-frames -1", kError, "--max-frames", l},
          {eval + "--pairs {out}/none.txt", kError, "none.txt", l},
          {eval + "--pairs {traj}/traj.tum", kError, "traj.tum", l},
      });
}

TEST(FuzzCliOptions, Graph) {
  const std::string opt = "graph optimize -q {g2o} {out}/o.g2o --json {out}/o.json ";
  const std::vector<std::string> o = {"{out}/o.g2o", "{out}/o.json"};
  runTable("graph", {
                        {opt, kOk, "", o},
                        {opt + "--loss huber --loss-scale 2 --max-iterations 3 --threads 1", kOk, "", o},
                        {opt + "--max-iterations 0", kError, "--max-iterations", o},
                        {opt + "--max-iterations " + k2to70, kError, "--max-iterations", o},
                        {opt + "--loss-scale nan --loss cauchy", kError, "--loss-scale", o},
                        {opt + "--loss-scale 0 --loss cauchy", kError, "--loss-scale", o},
                        {opt + "--threads 0", kError, "--threads", o},
                        {"graph optimize -q {g2o} {out}/no/dir/o.g2o", kError, "o.g2o"},
                        {"graph optimize -q {g2o} {out}", kError, "{out}"},  // item 7: the output is a folder
                        {"graph optimize -q {traj}/traj.tum {out}/o.g2o", kError, "traj.tum", {"{out}/o.g2o"}},
                    });
}

TEST(FuzzCliOptions, FeaturesDetect) {
  const std::string det = "features detect --detector shi-tomasi {png} --json {out}/d.json ";
  const std::vector<std::string> j = {"{out}/d.json"};
  runTable("features_detect",
           {
               {det + "--draw {out}/d.png", kOk, "", {"{out}/d.json", "{out}/d.png"}},
               {"features detect -q --detector orb {png} --json {out}/d.json", kOk, "", j},  // item 11: -q was rejected
               {det + "--max -1", kError, "--max", j},
               {det + "--max " + k2to70, kError, "--max", j},
               {det + "--darken nan", kError, "--darken", j},  // item 10
               {det + "--darken -1", kError, "--darken", j},
               {det + "--darken 0.5 --seed -1", kError, "--seed", j},  // item 10
               {det + "--darken 0.5 --seed " + k2to70, kError, "--seed", j},
               {"features detect --detector superpoint --weights {weights} --input-size -8x8 {png} --json {out}/d.json",
                kError, "--input-size", j},
               {"features detect --detector superpoint --weights {weights} --input-size 99999992x8 {png} --json "
                "{out}/d.json",
                kError, "--input-size", j},
               {"features detect --detector superpoint --weights {traj}/traj.tum {png} --json {out}/d.json", kError,
                "traj.tum", j},
               {det + "--config {kitti}", kError, "{kitti}", j},                                       // item 8
               {"features detect --detector orb {bigpng} --json {out}/d.json", kError, "big.png", j},  // item 11
               {"features detect --detector orb {traj}/traj.tum --json {out}/d.json", kError, "traj.tum", j},
               {"features detect --detector orb {png} --json {out}", kError, "{out}"},  // item 7
               {"features detect --detector orb {png} --draw {out}/no/dir/d.png", kError, "d.png"},
           });
}

TEST(FuzzCliOptions, FeaturesTrack) {
  const std::string tr = "features track -q {sim} --format sim --detector shi-tomasi --out {out}/t ";
  const std::vector<std::string> t = {"{out}/t/tracks.json"};
  runTable(
      "features_track",
      {
          {tr + "--overlay-every 2", kOk, "", t},
          {"features track -q {euroc} --format euroc --detector orb --out {out}/t", Expect::kEither, "{euroc}", t},
          {tr + "--overlay-every -1", kError, "--overlay-every", t},
          {tr + "--max-frames -1", kError, "--max-frames", t},  // item 10
          {tr + "--max-frames " + k2to70, kError, "--max-frames", t},
          {tr + "--start nan", kError, "--start", t},
          {tr + "--duration nan", kError, "--duration", t},
          {"features track -q {sim} --format sim --detector orb --config {kitti} --out {out}/t", kError, "{kitti}", t},
          {"features track -q {sim} --format sim --detector orb --out {traj}/traj.tum", kError, "traj.tum"},  // item 7
          {"features track -q {sim} --format kitti --detector orb --out {out}/t", kError, "{sim}", t},
      });
}

}  // namespace
}  // namespace drover::test::fuzz
