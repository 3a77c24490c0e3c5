#pragma once
// Strict text parsing for dataset and trajectory files. Every parse either returns a finite, fully consumed
// value or throws IoError naming the file and the record ("line 12"), so readers never guess.
//
// Stable API: other readers (EuRoC, KITTI, configs) rely on it. Add functions; do not change these.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "types/time.hpp"

namespace drover::io {

// One line of a text file with its 1-based line number (for error messages).
struct NumberedLine {
  std::size_t number = 0;
  std::string text;  // without the line terminator ("\n" or "\r\n")
};

// "line 12"
std::string lineRecord(std::size_t number);

// The whole file as bytes. Throws IoError "cannot open" / "read failed".
std::string readTextFile(const std::string& path);

// The file's lines that are neither blank nor comments (first non-blank character in `comment_chars`),
// numbered as in the file. Throws IoError when the file cannot be read.
std::vector<NumberedLine> readDataLines(const std::string& path, std::string_view comment_chars = "#");

// Leading and trailing spaces, tabs, '\r' removed.
std::string_view trim(std::string_view s);
// Fields separated by runs of spaces/tabs; empty fields never appear.
std::vector<std::string_view> splitWhitespace(std::string_view line);
// Fields separated by `sep`, each trimmed; "a,,b" gives an empty middle field (callers reject it on parse).
std::vector<std::string_view> splitOn(std::string_view line, char sep);

// Throws IoError "expected N columns, found M" unless fields.size() == n (or >= n for the AtLeast form).
void requireColumns(const std::vector<std::string_view>& fields, std::size_t n, const std::string& file,
                    const std::string& record);
void requireAtLeastColumns(const std::vector<std::string_view>& fields, std::size_t n, const std::string& file,
                           const std::string& record);

// Whole token must be a finite number ("1e-3", "-2.5"); NaN, inf, "", "1.5x" throw IoError.
double parseDouble(std::string_view token, const std::string& file, const std::string& record);
std::int64_t parseInt64(std::string_view token, const std::string& file, const std::string& record);
// Seconds as written in text ("1403715274.302142977", "1.037359e-01") to nanoseconds. Plain decimals are
// converted digit by digit, so they are exact to the nanosecond at any epoch (a double would lose ~100 ns
// at Unix-epoch scale); exponent forms go through a double. Digits beyond 1 ns are rounded half up.
Time parseSeconds(std::string_view token, const std::string& file, const std::string& record);
// Parses fields[first], ..., fields[first + count - 1] with parseDouble.
std::vector<double> parseDoubles(const std::vector<std::string_view>& fields, std::size_t first, std::size_t count,
                                 const std::string& file, const std::string& record);

// A times file: one time in seconds a line (KITTI times.txt), '#' and blank lines skipped, strictly
// increasing. Throws IoError naming the line otherwise.
std::vector<Time> readTimesFile(const std::string& path);

// Pose checks shared by readers. Tolerances are for values printed with ~7 significant digits.
constexpr double kRotationTolerance = 1e-3;    // max |R^T R - I| entry accepted, then re-orthonormalised
constexpr double kQuaternionTolerance = 1e-3;  // max | |q| - 1 | accepted, then normalised

// Throws IoError when R is not a rotation within kRotationTolerance (or is a reflection); otherwise returns
// the nearest rotation (SVD projection), so tiny print rounding does not leak into poses.
Eigen::Matrix3d checkedRotation(const Eigen::Matrix3d& R, const std::string& file, const std::string& record);
// Throws IoError when | |q| - 1 | > kQuaternionTolerance; otherwise returns q normalised.
Eigen::Quaterniond checkedQuaternion(double w, double x, double y, double z, const std::string& file,
                                     const std::string& record);
// Throws IoError "duplicate timestamp" / "timestamp goes backwards" unless t > previous.
void requireIncreasingTime(Time previous, Time t, const std::string& file, const std::string& record);

// For sensor streams, which drop a measurement whose stamp does not advance instead of failing: "" when
// t > previous, else the warning "FILE (RECORD): dropped: timestamp T s repeats the previous one" (or "goes back
// to T s from P s").
std::string staleStampNotice(Time previous, Time t, const std::string& file, const std::string& record);

// Shortest text that reads back to exactly the same double (std::to_chars); "nan"/"inf" never reach files
// because writers validate first.
std::string formatDouble(double value);
// A YAML flow sequence of formatDouble()s: "[1, -0.5, 3e-05]".
std::string formatNumberList(const std::vector<double>& values);
// The 16 entries of a 4x4 transform, row after row, as formatNumberList (EuRoC's T_BS data, calibration.yaml).
std::string formatRowMajor(const Eigen::Isometry3d& T);
// Nanoseconds as seconds with exactly 9 decimals ("-0.000000001", "1403715274.302142977").
std::string formatSeconds(Time t);

}  // namespace drover::io
