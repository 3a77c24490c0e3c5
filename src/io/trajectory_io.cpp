#include "io/trajectory_io.hpp"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "io/error.hpp"
#include "io/text_parsing.hpp"

namespace drover::io {

TrajectoryFormat parseTrajectoryFormat(const std::string& name) {
  if (name == "tum") return TrajectoryFormat::kTum;
  if (name == "kitti") return TrajectoryFormat::kKitti;
  if (name == "euroc") return TrajectoryFormat::kEuroc;
  throw std::invalid_argument("unknown trajectory format '" + name + "' (expected tum, kitti or euroc)");
}

namespace {

Eigen::Isometry3d poseFrom(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

void requireNotEmpty(const Trajectory& trajectory, const std::string& path) {
  if (trajectory.empty()) fail(path, "", "no poses in file");
}

// Readers only append in strictly increasing time; the previous pose's time is the reference.
void appendInOrder(Trajectory& trajectory, const StampedPose& pose, const std::string& path,
                   const std::string& record) {
  if (!trajectory.empty()) requireIncreasingTime(trajectory.back().t, pose.t, path, record);
  trajectory.push_back(pose);
}

// Writers refuse what a reader would reject, so every written file reads back.
void validateForWrite(const Trajectory& trajectory, const std::string& path) {
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    const auto& p = trajectory[i];
    if (!p.T_world_body.matrix().allFinite())
      throw std::invalid_argument("cannot write " + path + ": pose " + std::to_string(i) + " is not finite");
    if (i > 0 && p.t <= trajectory[i - 1].t)
      throw std::invalid_argument("cannot write " + path + ": pose " + std::to_string(i) +
                                  " is not after the previous one in time");
  }
}

std::string joinNumbers(std::initializer_list<double> values, const char* sep) {
  std::string s;
  for (double v : values) {
    if (!s.empty()) s += sep;
    s += formatDouble(v);
  }
  return s;
}

}  // namespace

Trajectory readTum(const std::string& path) {
  Trajectory trajectory;
  for (const auto& line : readDataLines(path, "#")) {
    const std::string record = lineRecord(line.number);
    const auto f = splitWhitespace(line.text);
    requireColumns(f, 8, path, record);
    const Time t = parseSeconds(f[0], path, record);
    const auto v = parseDoubles(f, 1, 7, path, record);
    const Eigen::Quaterniond q = checkedQuaternion(v[6], v[3], v[4], v[5], path, record);
    appendInOrder(trajectory, {t, poseFrom(q.toRotationMatrix(), {v[0], v[1], v[2]})}, path, record);
  }
  requireNotEmpty(trajectory, path);
  return trajectory;
}

Trajectory readKitti(const std::string& path, const std::optional<std::string>& times_path) {
  Trajectory trajectory;
  const auto lines = readDataLines(path, "#");
  std::vector<Time> times;
  if (times_path) {
    times = readTimesFile(*times_path);
    if (times.size() != lines.size())
      fail(*times_path, "",
           "has " + std::to_string(times.size()) + " times but " + path + " has " + std::to_string(lines.size()) +
               " poses");
  }
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string record = lineRecord(lines[i].number);
    const auto f = splitWhitespace(lines[i].text);
    requireColumns(f, 12, path, record);
    const auto v = parseDoubles(f, 0, 12, path, record);
    Eigen::Matrix3d R;
    R << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
    const Time t = times_path ? times[i] : static_cast<Time>(i) * kNanosPerSecond;
    appendInOrder(trajectory, {t, poseFrom(checkedRotation(R, path, record), {v[3], v[7], v[11]})}, path, record);
  }
  requireNotEmpty(trajectory, path);
  return trajectory;
}

Trajectory readEurocCsv(const std::string& path) {
  Trajectory trajectory;
  for (const auto& line : readDataLines(path, "#")) {
    const std::string record = lineRecord(line.number);
    const auto f = splitOn(line.text, ',');
    requireAtLeastColumns(f, 8, path, record);
    const Time t = parseInt64(f[0], path, record);
    const auto v = parseDoubles(f, 1, 7, path, record);
    const Eigen::Quaterniond q = checkedQuaternion(v[3], v[4], v[5], v[6], path, record);
    appendInOrder(trajectory, {t, poseFrom(q.toRotationMatrix(), {v[0], v[1], v[2]})}, path, record);
  }
  requireNotEmpty(trajectory, path);
  return trajectory;
}

Trajectory readTrajectory(const std::string& path, TrajectoryFormat format,
                          const std::optional<std::string>& times_path) {
  if (times_path && format != TrajectoryFormat::kKitti)
    throw std::invalid_argument("a times file applies to KITTI trajectories only (" + path + ")");
  switch (format) {
    case TrajectoryFormat::kTum: return readTum(path);
    case TrajectoryFormat::kKitti: return readKitti(path, times_path);
    case TrajectoryFormat::kEuroc: return readEurocCsv(path);
  }
  throw std::invalid_argument("unknown trajectory format");
}

Eigen::Quaterniond canonicalQuaternion(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q = Eigen::Quaterniond(R).normalized();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  return q;
}

namespace {

constexpr const char* kTumHeader = "# t[s] x y z qx qy qz qw (T_world_body)\n";

std::string tumLine(const StampedPose& p) {
  const Eigen::Quaterniond q = canonicalQuaternion(p.T_world_body.linear());
  const Eigen::Vector3d& x = p.T_world_body.translation();
  return formatSeconds(p.t) + " " + joinNumbers({x.x(), x.y(), x.z(), q.x(), q.y(), q.z(), q.w()}, " ") + "\n";
}
}  // namespace

void writeTum(const std::string& path, const Trajectory& trajectory) {
  validateForWrite(trajectory, path);
  std::string out = kTumHeader;
  for (const auto& p : trajectory) out += tumLine(p);
  writeFileAtomically(path, out);
}

TumStream::TumStream(std::string path) : path_(std::move(path)), file_(std::fopen(path_.c_str(), "w")) {
  if (file_ == nullptr) throw IoError(path_, "", std::string("cannot open for writing: ") + std::strerror(errno));
  if (std::fputs(kTumHeader, file_) < 0) throw IoError(path_, "", "write failed");
}

TumStream::~TumStream() {
  if (file_ != nullptr) std::fclose(file_);
}

void TumStream::add(const StampedPose& pose) {
  if (file_ == nullptr) throw std::logic_error("TumStream::add after close: " + path_);
  validateForWrite({pose}, path_);
  if (count_ > 0 && pose.t <= last_)
    throw std::invalid_argument("cannot write " + path_ + ": pose " + std::to_string(count_) +
                                " is not after the previous one in time");
  if (std::fputs(tumLine(pose).c_str(), file_) < 0) throw IoError(path_, "pose " + std::to_string(count_), "write failed");
  ++count_;
  last_ = pose.t;
}

void TumStream::flush() {
  if (file_ != nullptr && (std::fflush(file_) != 0 || std::ferror(file_) != 0))
    throw IoError(path_, "", "write failed (disk full?)");
}

void TumStream::close() {
  if (file_ == nullptr) return;
  const bool ok = std::fflush(file_) == 0 && std::ferror(file_) == 0;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!ok || !closed) throw IoError(path_, "", "write failed (disk full?)");
}

void writeKitti(const std::string& path, const Trajectory& trajectory,
                const std::optional<std::string>& times_path) {
  validateForWrite(trajectory, path);
  std::string out, times;
  for (const auto& p : trajectory) {
    const Eigen::Matrix<double, 3, 4> M = p.T_world_body.matrix().topRows<3>();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) out += formatDouble(M(r, c)) + (r == 2 && c == 3 ? "\n" : " ");
    times += formatSeconds(p.t) + "\n";
  }
  writeFileAtomically(path, out);
  if (times_path) writeFileAtomically(*times_path, times);
}

void writeEurocCsv(const std::string& path, const Trajectory& trajectory) {
  validateForWrite(trajectory, path);
  std::string out = "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z []\n";
  for (const auto& p : trajectory) {
    const Eigen::Quaterniond q = canonicalQuaternion(p.T_world_body.linear());
    const Eigen::Vector3d& x = p.T_world_body.translation();
    out += std::to_string(p.t) + "," + joinNumbers({x.x(), x.y(), x.z(), q.w(), q.x(), q.y(), q.z()}, ",") + "\n";
  }
  writeFileAtomically(path, out);
}

void writeTrajectory(const std::string& path, TrajectoryFormat format, const Trajectory& trajectory) {
  switch (format) {
    case TrajectoryFormat::kTum: return writeTum(path, trajectory);
    case TrajectoryFormat::kKitti: return writeKitti(path, trajectory);
    case TrajectoryFormat::kEuroc: return writeEurocCsv(path, trajectory);
  }
  throw std::invalid_argument("unknown trajectory format");
}

void writeFileAtomically(const std::string& path, const std::string& content) {
  namespace fs = std::filesystem;
  // The temporary sits beside the target so the rename stays on one file system (and is atomic there).
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) fail(path, "", "cannot create temporary file " + tmp);
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.flush();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      fail(path, "", "write failed (disk full?)");
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    fail(path, "", "cannot replace file: " + ec.message());
  }
}

}  // namespace drover::io
