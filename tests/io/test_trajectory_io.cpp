#include "io/trajectory_io.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/error.hpp"
#include "support/shared_data.hpp"
#include "support/expect_io_error.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {

using test::TempDir;
using test::writeText;

// Poses with awkward values: large translations, ns-exact epoch times, all rotation axes.
Trajectory sampleTrajectory() {
  Trajectory traj;
  for (int i = 0; i < 5; ++i) {
    StampedPose p;
    p.t = 1403715274302142977LL + i * 5'000'001LL;
    const Eigen::Vector3d axis = Eigen::Vector3d(0.3 + i, -1.0, 0.7 * i).normalized();
    p.T_world_body.linear() = Eigen::AngleAxisd(0.1 + 0.9 * i, axis).toRotationMatrix();
    p.T_world_body.translation() = Eigen::Vector3d(1234.567890123 * i, -0.000123456789, 98765.4321 / (i + 1));
    traj.push_back(p);
  }
  return traj;
}

void expectSame(const Trajectory& a, const Trajectory& b, bool compare_times) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (compare_times) {
      EXPECT_EQ(a[i].t, b[i].t) << "pose " << i;
    }
    EXPECT_LT((a[i].T_world_body.matrix() - b[i].T_world_body.matrix()).cwiseAbs().maxCoeff(), 1e-9) << "pose " << i;
  }
}

using test::expectIoError;

TEST(TrajectoryIo, ParsesFormatNames) {
  EXPECT_EQ(parseTrajectoryFormat("tum"), TrajectoryFormat::kTum);
  EXPECT_EQ(parseTrajectoryFormat("kitti"), TrajectoryFormat::kKitti);
  EXPECT_EQ(parseTrajectoryFormat("euroc"), TrajectoryFormat::kEuroc);
  EXPECT_THROW(parseTrajectoryFormat("bag"), std::invalid_argument);
}

TEST(TrajectoryIo, TumRoundTripIsExactToTheNanosecondAnd1e9) {
  TempDir dir;
  const auto path = (dir / "t.tum").string();
  writeTum(path, sampleTrajectory());
  expectSame(sampleTrajectory(), readTum(path), true);
}

TEST(TrajectoryIo, TumStreamWritesWhatWriteTumWritesPoseByPose) {
  TempDir dir;
  const auto streamed = (dir / "s.tum").string(), whole = (dir / "w.tum").string();
  {
    TumStream out(streamed);
    for (const StampedPose& p : sampleTrajectory()) out.add(p);
    EXPECT_EQ(out.size(), sampleTrajectory().size());
    out.close();
    out.close();  // idempotent
  }
  writeTum(whole, sampleTrajectory());
  std::ifstream a(streamed), b(whole);
  std::stringstream sa, sb;
  sa << a.rdbuf();
  sb << b.rdbuf();
  EXPECT_EQ(sa.str(), sb.str());
  expectSame(sampleTrajectory(), readTum(streamed), true);
}

TEST(TrajectoryIo, TumStreamRefusesAPoseNotAfterThePreviousAndAFolderItCannotWriteIn) {
  TempDir dir;
  TumStream out((dir / "s.tum").string());
  out.add(sampleTrajectory()[1]);
  EXPECT_THROW(out.add(sampleTrajectory()[0]), std::invalid_argument);
  StampedPose bad = sampleTrajectory()[2];
  bad.T_world_body.translation().x() = std::nan("");
  EXPECT_THROW(out.add(bad), std::invalid_argument);
  const std::string missing = (dir / "no_such_folder" / "s.tum").string();
  expectIoError([&] { TumStream s(missing); }, {missing, "cannot open for writing"});
}

TEST(TrajectoryIo, EurocRoundTripIsExact) {
  TempDir dir;
  const auto path = (dir / "gt.csv").string();
  writeEurocCsv(path, sampleTrajectory());
  expectSame(sampleTrajectory(), readEurocCsv(path), true);
}

TEST(TrajectoryIo, KittiRoundTripWithTimesFileKeepsTimes) {
  TempDir dir;
  const auto path = (dir / "poses.txt").string(), times = (dir / "times.txt").string();
  writeKitti(path, sampleTrajectory(), times);
  expectSame(sampleTrajectory(), readKitti(path, times), true);
}

TEST(TrajectoryIo, KittiWithoutTimesFileNumbersPosesBySecond) {
  TempDir dir;
  const auto path = (dir / "poses.txt").string();
  writeTrajectory(path, TrajectoryFormat::kKitti, sampleTrajectory());
  const Trajectory read = readTrajectory(path, TrajectoryFormat::kKitti);
  expectSame(sampleTrajectory(), read, false);
  for (std::size_t i = 0; i < read.size(); ++i) EXPECT_EQ(read[i].t, static_cast<Time>(i) * kNanosPerSecond);
}

TEST(TrajectoryIo, WriteReplacesExistingFileAndLeavesNoTemporary) {
  TempDir dir;
  const auto path = (dir / "t.tum").string();
  writeText(path, "garbage that is longer than anything\n");
  writeTum(path, sampleTrajectory());
  expectSame(sampleTrajectory(), readTum(path), true);
  int files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 1);
}

TEST(TrajectoryIo, WriteIntoMissingFolderThrowsIoError) {
  TempDir dir;
  EXPECT_THROW(writeTum((dir / "no/such/t.tum").string(), sampleTrajectory()), IoError);
}

TEST(TrajectoryIo, TumNormalisesSlightlyNonUnitQuaternion) {
  TempDir dir;
  writeText(dir / "t.tum", "# comment\n\n1.5 1 2 3 0 0 0.7071 0.7075\n");
  const Trajectory t = readTum((dir / "t.tum").string());
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t[0].t, 1'500'000'000);
  const Eigen::Quaterniond q(t[0].T_world_body.linear());
  EXPECT_NEAR(q.norm(), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(q.z()), 0.7071 / std::hypot(0.7071, 0.7075), 1e-12);
}

TEST(TrajectoryIo, WritersPutQuaternionsInTheHemisphereWithNonNegativeW) {
  TempDir dir;
  Trajectory traj(1);
  traj[0].t = 1'000'000'000;
  // 170 deg about -z: the trace is negative, so Eigen's matrix->quaternion makes the dominant component (z)
  // positive and returns w = -cos(85 deg) < 0. The file must hold the twin with w = +cos(85 deg).
  traj[0].T_world_body.linear() = Eigen::AngleAxisd(170.0 * M_PI / 180.0, -Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (const auto format : {TrajectoryFormat::kTum, TrajectoryFormat::kEuroc}) {
    const std::string path = (dir / "q.txt").string();
    writeTrajectory(path, format, traj);
    std::ifstream in(path);
    std::string header, line;
    std::getline(in, header);
    std::getline(in, line);
    for (char& c : line) c = c == ',' ? ' ' : c;
    std::istringstream fields(line);
    double v[8];
    for (double& x : v) fields >> x;
    const double w = format == TrajectoryFormat::kTum ? v[7] : v[4];
    EXPECT_NEAR(w, std::cos(85.0 * M_PI / 180.0), 1e-9) << line;
    expectSame(readTrajectory(path, format), traj, true);
  }
}

TEST(TrajectoryIo, RejectsMissingFile) {
  expectIoError([] { readTum("/nonexistent/drover/t.tum"); }, {"/nonexistent/drover/t.tum", "cannot open"});
  expectIoError([] { readKitti("/nonexistent/drover/p.txt"); }, {"cannot open"});
  expectIoError([] { readEurocCsv("/nonexistent/drover/d.csv"); }, {"cannot open"});
}

TEST(TrajectoryIo, RejectsWrongColumnCountNamingTheLine) {
  TempDir dir;
  writeText(dir / "t.tum", "0 0 0 0 0 0 0 1\n1 0 0 0 0 0 1\n");
  expectIoError([&] { readTum((dir / "t.tum").string()); }, {"line 2", "expected 8 columns, found 7"});
  writeText(dir / "k.txt", "1 0 0 0 0 1 0 0 0 0 1 0 5\n");
  expectIoError([&] { readKitti((dir / "k.txt").string()); }, {"line 1", "expected 12 columns, found 13"});
  writeText(dir / "e.csv", "#h\n1,0,0,0,1,0,0\n");
  expectIoError([&] { readEurocCsv((dir / "e.csv").string()); }, {"line 2", "at least 8 columns"});
}

TEST(TrajectoryIo, RejectsNanAndInf) {
  TempDir dir;
  writeText(dir / "a.tum", "0 nan 0 0 0 0 0 1\n");
  expectIoError([&] { readTum((dir / "a.tum").string()); }, {"line 1", "nan"});
  writeText(dir / "b.tum", "0 0 0 0 0 0 0 1\n1 0 inf 0 0 0 0 1\n");
  expectIoError([&] { readTum((dir / "b.tum").string()); }, {"line 2", "inf"});
  writeText(dir / "k.txt", "1 0 0 0 0 1 0 NaN 0 0 1 0\n");
  expectIoError([&] { readKitti((dir / "k.txt").string()); }, {"line 1"});
  writeText(dir / "c.tum", "0 1x 0 0 0 0 0 1\n");
  expectIoError([&] { readTum((dir / "c.tum").string()); }, {"line 1", "not a number: '1x'"});
}

TEST(TrajectoryIo, RejectsNonUnitQuaternion) {
  TempDir dir;
  writeText(dir / "t.tum", "0 0 0 0 0 0 0 1.01\n");
  expectIoError([&] { readTum((dir / "t.tum").string()); }, {"line 1", "quaternion is not unit"});
  writeText(dir / "e.csv", "5,0,0,0,0,0,0,0\n");
  expectIoError([&] { readEurocCsv((dir / "e.csv").string()); }, {"line 1", "quaternion is not unit"});
}

TEST(TrajectoryIo, KittiOrthonormalisesRoundedRotationButRejectsSkewedOne) {
  TempDir dir;
  // cos/sin of 0.3 rad printed with 4 decimals: off by ~5e-5, within tolerance.
  writeText(dir / "ok.txt", "0.9553 -0.2955 0 1 0.2955 0.9553 0 2 0 0 1 3\n");
  const Trajectory t = readKitti((dir / "ok.txt").string());
  const Eigen::Matrix3d R = t[0].T_world_body.linear();
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(std::atan2(R(1, 0), R(0, 0)), std::atan2(0.2955, 0.9553), 1e-9);
  EXPECT_EQ(t[0].T_world_body.translation(), Eigen::Vector3d(1, 2, 3));
  writeText(dir / "bad.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0.01 0 0 0 1 0 0 0 0 1 0\n");
  expectIoError([&] { readKitti((dir / "bad.txt").string()); }, {"line 2", "not orthonormal"});
  writeText(dir / "mirror.txt", "-1 0 0 0 0 1 0 0 0 0 1 0\n");
  expectIoError([&] { readKitti((dir / "mirror.txt").string()); }, {"line 1", "reflection"});
}

TEST(TrajectoryIo, RejectsBackwardsAndDuplicateTimestamps) {
  TempDir dir;
  writeText(dir / "dup.tum", "1 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n");
  expectIoError([&] { readTum((dir / "dup.tum").string()); }, {"line 2", "duplicate timestamp"});
  writeText(dir / "back.csv", "200,0,0,0,1,0,0,0\n100,0,0,0,1,0,0,0\n");
  expectIoError([&] { readEurocCsv((dir / "back.csv").string()); }, {"line 2", "backwards"});
  writeText(dir / "p.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 0\n");
  writeText(dir / "times.txt", "0.5\n0.4\n");
  expectIoError([&] { readKitti((dir / "p.txt").string(), (dir / "times.txt").string()); },
                {"times.txt", "line 2", "backwards"});
}

TEST(TrajectoryIo, RejectsTimesFileWhoseLineCountDiffers) {
  TempDir dir;
  writeText(dir / "p.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 0\n");
  writeText(dir / "times.txt", "0.0\n0.1\n0.2\n");
  expectIoError([&] { readKitti((dir / "p.txt").string(), (dir / "times.txt").string()); },
                {"times.txt", "has 3 times", "has 2 poses"});
}

TEST(TrajectoryIo, RejectsEmptyFile) {
  TempDir dir;
  writeText(dir / "t.tum", "# only a header\n");
  expectIoError([&] { readTum((dir / "t.tum").string()); }, {"no poses"});
}

TEST(TrajectoryIo, WritersRefuseWhatReadersWouldReject) {
  TempDir dir;
  Trajectory t = sampleTrajectory();
  t[2].t = t[1].t;
  EXPECT_THROW(writeTum((dir / "t.tum").string(), t), std::invalid_argument);
  t = sampleTrajectory();
  t[0].T_world_body.translation().x() = std::nan("");
  EXPECT_THROW(writeEurocCsv((dir / "e.csv").string(), t), std::invalid_argument);
}

TEST(TrajectoryIo, ReadsRealKittiPoses00) {
  const auto path = test::sharedData("kitti/poses/00.txt");
  DROVER_REQUIRE_SHARED(path);
  const Trajectory t = readKitti(path.string());
  ASSERT_EQ(t.size(), 4541u);
  // First pose is the identity up to the file's print rounding.
  EXPECT_LT((t.front().T_world_body.matrix() - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff(), 1e-6);
  // Last line: "... -5.583931 ... -3.562758 ... 96.96153"
  EXPECT_EQ(t.back().T_world_body.translation(), Eigen::Vector3d(-5.583931, -3.562758, 96.96153));
  EXPECT_NEAR(t.back().T_world_body.linear()(0, 0), 0.9989093, 1e-6);
  EXPECT_NEAR(t.back().T_world_body.linear()(2, 0), 0.04588779, 1e-6);
  EXPECT_EQ(t.back().t, 4540 * kNanosPerSecond);
}

TEST(TrajectoryIo, ReadsRealKittiPosesWithSequenceTimes) {
  const auto seq = test::sharedData("kitti/sequences/00");
  DROVER_REQUIRE_SHARED(seq);
  const Trajectory t = readKitti((seq / "poses.txt").string(), (seq / "times.txt").string());
  ASSERT_EQ(t.size(), 4541u);
  EXPECT_EQ(t[0].t, 0);
  EXPECT_EQ(t[1].t, 103'735'900);  // "1.037359e-01"
}

TEST(TrajectoryIo, ReadsRealEurocTumGroundTruth) {
  const auto path = test::sharedData("euroc/V1_01_easy_micro/groundtruth_tum.txt");
  DROVER_REQUIRE_SHARED(path);
  const Trajectory t = readTum(path.string());
  ASSERT_EQ(t.size(), 28712u);
  // "1403715274.30214 0.878612 2.142470 0.947262 -0.828459 -0.058956 -0.553641 0.060514"
  EXPECT_EQ(t.front().t, 1403715274302140000LL);
  EXPECT_EQ(t.front().T_world_body.translation(), Eigen::Vector3d(0.878612, 2.142470, 0.947262));
  const Eigen::Quaterniond q0 = Eigen::Quaterniond(0.060514, -0.828459, -0.058956, -0.553641).normalized();
  const Eigen::Quaterniond q0_read(t.front().T_world_body.linear());
  EXPECT_NEAR(std::abs(q0.dot(q0_read)), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(q0_read.x()), 0.828459 / Eigen::Vector4d(0.828459, 0.058956, 0.553641, 0.060514).norm(), 1e-12);
  // "1403715417.85714 0.489592 1.967734 0.967288 0.780946 -0.241803 0.554661 0.154937"
  EXPECT_EQ(t.back().t, 1403715417857140000LL);
  EXPECT_EQ(t.back().T_world_body.translation(), Eigen::Vector3d(0.489592, 1.967734, 0.967288));
}

}  // namespace
}  // namespace drover::io
