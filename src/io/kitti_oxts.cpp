#include "io/kitti_oxts.hpp"

#include <cmath>

#include "io/error.hpp"
#include "io/text_parsing.hpp"

namespace drover::io {

namespace {
constexpr double kEarthRadius = 6378137.0;  // [m] devkit's er
constexpr double kPi = 3.14159265358979323846;

Eigen::Matrix3d oxtsRotation(const OxtsRecord& r) {
  return (Eigen::AngleAxisd(r.yaw(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(r.pitch(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r.roll(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's days_from_civil).
std::int64_t daysFromCivil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const unsigned yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

bool digitsAt(std::string_view s, std::size_t pos, std::size_t n, int& out) {
  if (pos + n > s.size()) return false;
  out = 0;
  for (std::size_t i = pos; i < pos + n; ++i) {
    if (s[i] < '0' || s[i] > '9') return false;
    out = out * 10 + (s[i] - '0');
  }
  return true;
}
}  // namespace

OxtsRecord readOxtsFile(const std::string& path) {
  const auto lines = readDataLines(path, "#");
  if (lines.empty()) fail(path, "", "empty oxts file");
  if (lines.size() > 1) fail(path, lineRecord(lines[1].number), "expected one oxts record per file");
  const std::string record = lineRecord(lines[0].number);
  const auto f = splitWhitespace(lines[0].text);
  requireColumns(f, OxtsRecord::kFields, path, record);
  OxtsRecord r;
  for (std::size_t i = 0; i < OxtsRecord::kFields; ++i) r.v[i] = parseDouble(f[i], path, record);
  if (std::abs(r.lat()) >= 90.0) fail(path, record, "latitude out of range");
  return r;
}

ImuSample oxtsToImu(const OxtsRecord& r, Time t) {
  ImuSample s;
  s.t = t;
  s.omega_imu = Eigen::Vector3d(r.v[20], r.v[21], r.v[22]);  // wf, wl, wu
  s.acc_imu = Eigen::Vector3d(r.v[14], r.v[15], r.v[16]);    // af, al, au
  s.q_world_imu = Eigen::Quaterniond(oxtsRotation(r));
  return s;
}

Eigen::Vector2d latLonToMercator(double lat_deg, double lon_deg, double scale) {
  const double mx = scale * lon_deg * kPi * kEarthRadius / 180.0;
  const double my = scale * kEarthRadius * std::log(std::tan((90.0 + lat_deg) * kPi / 360.0));
  return {mx, my};
}

Trajectory oxtsToPoses(const std::vector<OxtsRecord>& records, const std::vector<Time>& times) {
  Trajectory poses;
  if (records.empty()) return poses;
  const double scale = std::cos(records.front().lat() * kPi / 180.0);
  Eigen::Isometry3d T_first_inv = Eigen::Isometry3d::Identity();
  for (std::size_t i = 0; i < records.size(); ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = oxtsRotation(records[i]);
    T.translation() << latLonToMercator(records[i].lat(), records[i].lon(), scale), records[i].alt();
    if (i == 0) T_first_inv = T.inverse();
    poses.push_back({times.at(i), T_first_inv * T});
  }
  return poses;
}

Time parseKittiTimestamp(std::string_view text, const std::string& file, const std::string& record) {
  const std::string_view s = trim(text);
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;
  const bool shape_ok = digitsAt(s, 0, 4, year) && s.size() > 4 && s[4] == '-' && digitsAt(s, 5, 2, month) &&
                        s.size() > 7 && s[7] == '-' && digitsAt(s, 8, 2, day) && s.size() > 10 && s[10] == ' ' &&
                        digitsAt(s, 11, 2, hour) && s.size() > 13 && s[13] == ':' && digitsAt(s, 14, 2, minute) &&
                        s.size() > 16 && s[16] == ':' && digitsAt(s, 17, 2, second);
  const auto bad = [&](const char* why) {
    fail(file, record, std::string(why) + ": '" + std::string(s) + "' (expected YYYY-MM-DD HH:MM:SS.fffffffff)");
  };
  if (!shape_ok) bad("unparsable timestamp");
  if (month < 1 || month > 12 || day < 1 || day > 31 || hour > 23 || minute > 59 || second > 59)
    bad("timestamp out of range");
  Time nanos = 0;
  if (s.size() > 19) {
    const std::string_view frac = s.substr(20);
    if (s[19] != '.' || frac.empty() || frac.size() > 9) bad("unparsable timestamp");
    int digit = 0;
    for (std::size_t i = 0; i < 9; ++i) {
      if (i < frac.size() && !digitsAt(frac, i, 1, digit)) bad("unparsable timestamp");
      nanos = nanos * 10 + (i < frac.size() ? digit : 0);
    }
  }
  const std::int64_t days = daysFromCivil(year, static_cast<unsigned>(month), static_cast<unsigned>(day));
  const std::int64_t secs = days * 86400 + hour * 3600 + minute * 60 + second;
  return secs * kNanosPerSecond + nanos;
}

std::vector<Time> readKittiTimestampsAsListed(const std::string& path) {
  std::vector<Time> times;
  for (const auto& line : readDataLines(path, "#"))
    times.push_back(parseKittiTimestamp(line.text, path, lineRecord(line.number)));
  return times;
}

std::vector<Time> readKittiTimestamps(const std::string& path) {
  std::vector<Time> times;
  for (const auto& line : readDataLines(path, "#")) {
    const std::string record = lineRecord(line.number);
    const Time t = parseKittiTimestamp(line.text, path, record);
    if (!times.empty()) requireIncreasingTime(times.back(), t, path, record);
    times.push_back(t);
  }
  return times;
}

}  // namespace drover::io
