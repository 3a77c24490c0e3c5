// Fuzzing the KITTI readers (odometry: velodyne .bin, calib.txt, times.txt, poses.txt, PNGs; raw: oxts, timestamps,
// calibration files, scans, PNGs): a few hundred mutated inputs each must read cleanly or end in one short
// io::IoError naming the file -- never another exception, a crash, a hang or non-finite data (reader_fuzz.hpp).
#include <gtest/gtest.h>

#include <cstring>
#include <limits>

#include "fuzz/fixtures.hpp"
#include "fuzz/reader_fuzz.hpp"
#include "io/dataset.hpp"
#include "io/kitti_common.hpp"

namespace drover::test::fuzz {
namespace {

std::string readKittiDataset(const fs::path& dir, const std::string& format) {
  auto reader = io::openDataset(dir.string(), format, io::DatasetOptions{});
  return checkStream(*reader, true);
}

TEST(FuzzKittiOdometry, MutatedSequencesReadCleanlyOrFailWithOneIoErrorNamingTheFile) {
  ReaderTarget t;
  t.name = "kitti odometry";
  t.write_fixture = [](const fs::path& root) { writeKittiSequence(root / "00", 4, 6, 24); };
  t.files = {{"00/times.txt"},
             {"00/calib.txt"},
             {"00/calib.txt"},
             {"00/poses.txt"},
             {"00/velodyne/000000.bin", true, 16},
             {"00/velodyne/000002.bin", true, 16},
             {"00/image_2/000001.png", true, 1}};
  t.read = [](const fs::path& root) { return readKittiDataset(root / "00", "kitti"); };
  // Item 9 of issue 14: one NaN point (README: "NaN/inf points are dropped").
  std::string bin, calib;  // from a scratch copy of the fixture
  TempDir scratch;
  writeKittiSequence(scratch / "00", 4, 6, 24);
  bin = readText(scratch / "00/velodyne/000000.bin");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(bin.data() + 16 * 3, &nan, 4);
  t.extra.push_back({"00/velodyne/000000.bin", {"x of point 3 -> NaN", bin}, "000000.bin"});
  // Item 11: a P2 of zeros (fx 0) and a malformed Tr.
  calib = readText(scratch / "00/calib.txt");
  std::string zeros = calib;
  zeros.replace(zeros.find("P2: "), zeros.find('\n', zeros.find("P2: ")) - zeros.find("P2: "),
                "P2: 0 0 0 0 0 0 0 0 0 0 0 0");
  t.extra.push_back({"00/calib.txt", {"P2 all zeros", zeros}, "P2"});
  std::string bad_tr = calib;
  bad_tr.replace(bad_tr.find("Tr: 0 -1"), 8, "Tr: 0 -1x");
  t.extra.push_back({"00/calib.txt", {"Tr with a malformed number", bad_tr}, "Tr", "missing"});
  runCampaign(t, 400);
}

TEST(FuzzKittiRaw, MutatedDrivesReadCleanlyOrFailWithOneIoErrorNamingTheFile) {
  ReaderTarget t;
  t.name = "kitti raw";
  const std::string d = "2011_09_30_drive_0018_sync/";
  t.write_fixture = [d](const fs::path& root) { writeKittiRawDrive(root / d); };
  t.files = {{d + "oxts/data/0000000003.txt"},
             {d + "oxts/data/0000000000.txt"},
             {d + "oxts/timestamps.txt"},
             {d + "velodyne_points/timestamps_start.txt"},
             {d + "velodyne_points/timestamps_end.txt"},
             {d + "velodyne_points/data/0000000001.bin", true, 16},
             {d + "calib_imu_to_velo.txt"},
             {d + "calib_velo_to_cam.txt"},
             {d + "calib_cam_to_cam.txt"},
             {d + "image_02/timestamps.txt"},
             {d + "image_02/data/0000000000.png", true, 1}};
  t.read = [d](const fs::path& root) { return readKittiDataset(root / d, "kitti-raw"); };
  runCampaign(t, 400);
}

TEST(FuzzKittiBin, ALoopPairScanReadsOrFailsNamingTheFile) {
  // `drover loop pair` reads single .bin files with readKittiBin: the same contract on a lone scan.
  ReaderTarget t;
  t.name = "kitti .bin";
  t.write_fixture = [](const fs::path& root) { writeBin(root / "a.bin", hallScan(0, 8, 32)); };
  t.files = {{"a.bin", true, 16}};
  t.read = [](const fs::path& root) {
    const LidarScan s = io::readKittiBin((root / "a.bin").string(), 0, 0);
    for (const LidarPoint& p : s.points)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(p.intensity))
        return std::string("a non-finite point was returned");
    return std::string();
  };
  runCampaign(t, 200);
}

}  // namespace
}  // namespace drover::test::fuzz
