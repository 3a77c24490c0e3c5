#pragma once
// KITTI raw OXTS RT3003 GPS/IMU records and KITTI raw timestamp strings (devkit readme, Geiger et al., IJRR 2013).
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "types/imu.hpp"
#include "types/time.hpp"
#include "types/trajectory.hpp"

namespace drover::io {

// One oxts/data/NNNNNNNNNN.txt line: 30 numbers, in this order (devkit dataformat.txt):
//  0 lat [deg]  1 lon [deg]  2 alt [m]  3 roll  4 pitch  5 yaw [rad] (yaw 0 = east, counter-clockwise)
//  6 vn  7 ve  8 vf  9 vl  10 vu [m/s]   11 ax  12 ay  13 az  14 af  15 al  16 au [m/s^2]
//  17 wx  18 wy  19 wz  20 wf  21 wl  22 wu [rad/s]   23 pos_accuracy  24 vel_accuracy  25 navstat
//  26 numsats  27 posmode  28 velmode  29 orimode
struct OxtsRecord {
  static constexpr std::size_t kFields = 30;
  std::array<double, kFields> v{};
  double lat() const { return v[0]; }
  double lon() const { return v[1]; }
  double alt() const { return v[2]; }
  double roll() const { return v[3]; }
  double pitch() const { return v[4]; }
  double yaw() const { return v[5]; }
};

// Reads one oxts data file (exactly one line of 30 finite numbers). Throws IoError naming file and line.
OxtsRecord readOxtsFile(const std::string& path);

// The IMU sample of a record in the OXTS forward-left-up frame, as kitti2bag publishes it:
// omega_imu = (wf, wl, wu), acc_imu = (af, al, au) (specific force, gravity included);
// q_world_imu = Rz(yaw) Ry(pitch) Rx(roll), world = local east-north-up.
ImuSample oxtsToImu(const OxtsRecord& record, Time t);

// Devkit convertOxtsToPose: Mercator position (scale = cos(lat0), er = 6378137 m) and R = Rz(yaw) Ry(pitch) Rx(roll),
// each pose expressed relative to the first (T_0^-1 T_i), i.e. T_world_imu with world = first IMU pose.
Trajectory oxtsToPoses(const std::vector<OxtsRecord>& records, const std::vector<Time>& times);

// Mercator of the devkit (latlonToMercator) for a given scale = cos(lat0 * pi / 180), metres.
Eigen::Vector2d latLonToMercator(double lat_deg, double lon_deg, double scale);

// "2011-09-30 12:40:21.123456789" (1 to 9 fractional digits, or none) -> ns since 1970-01-01 00:00:00 with the
// date-time read as if it were UTC. KITTI writes local time (CEST) without a zone; only differences matter and
// the epoch stays fixed for every file of a drive. Throws IoError naming file and record when malformed.
Time parseKittiTimestamp(std::string_view text, const std::string& file, const std::string& record);
// A timestamps.txt: one such string a line, strictly increasing (IoError naming the line otherwise).
std::vector<Time> readKittiTimestamps(const std::string& path);
// The same without the order check, one time per data line (entry i = the drive's file i): for readers that drop
// a measurement whose stamp does not advance. Lines are numbered i + 1 when the file has no blank or '#' lines.
std::vector<Time> readKittiTimestampsAsListed(const std::string& path);

}  // namespace drover::io
