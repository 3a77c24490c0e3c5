#include "io/text_parsing.hpp"

#include <Eigen/SVD>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "io/error.hpp"

namespace drover::io {

std::string lineRecord(std::size_t number) { return "line " + std::to_string(number); }

std::string readTextFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "", "cannot open file");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) fail(path, "", "read failed");
  return ss.str();
}

std::vector<NumberedLine> readDataLines(const std::string& path, std::string_view comment_chars) {
  const std::string content = readTextFile(path);
  std::vector<NumberedLine> lines;
  std::size_t number = 0;
  std::size_t begin = 0;
  while (begin < content.size()) {
    std::size_t end = content.find('\n', begin);
    if (end == std::string::npos) end = content.size();
    ++number;
    std::string_view line(content.data() + begin, end - begin);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::string_view t = trim(line);
    if (!t.empty() && comment_chars.find(t.front()) == std::string_view::npos)
      lines.push_back({number, std::string(line)});
    begin = end + 1;
  }
  return lines;
}

std::string_view trim(std::string_view s) {
  const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> splitWhitespace(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

std::vector<std::string_view> splitOn(std::string_view line, char sep) {
  std::vector<std::string_view> fields;
  std::size_t begin = 0;
  while (true) {
    const std::size_t end = line.find(sep, begin);
    fields.push_back(trim(line.substr(begin, end == std::string_view::npos ? std::string_view::npos : end - begin)));
    if (end == std::string_view::npos) break;
    begin = end + 1;
  }
  return fields;
}

void requireColumns(const std::vector<std::string_view>& fields, std::size_t n, const std::string& file,
                    const std::string& record) {
  if (fields.size() != n)
    fail(file, record, "expected " + std::to_string(n) + " columns, found " + std::to_string(fields.size()));
}

void requireAtLeastColumns(const std::vector<std::string_view>& fields, std::size_t n, const std::string& file,
                           const std::string& record) {
  if (fields.size() < n)
    fail(file, record,
         "expected at least " + std::to_string(n) + " columns, found " + std::to_string(fields.size()));
}

double parseDouble(std::string_view token, const std::string& file, const std::string& record) {
  std::string_view s = token;
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);  // from_chars rejects a leading '+'
  double value = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec != std::errc() || ptr != s.data() + s.size())
    fail(file, record, "not a number: " + echo(token));
  if (!std::isfinite(value)) fail(file, record, "non-finite value " + echo(token));
  return value;
}

std::int64_t parseInt64(std::string_view token, const std::string& file, const std::string& record) {
  std::string_view s = token;
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  std::int64_t value = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec != std::errc() || ptr != s.data() + s.size())
    fail(file, record, "not an integer: " + echo(token));
  return value;
}

namespace {
bool isDigit(char c) { return c >= '0' && c <= '9'; }

// "[+-]digits[.digits]" or "[+-].digits"; anything else (exponents, junk) is not plain.
bool isPlainDecimal(std::string_view s) {
  std::size_t i = (!s.empty() && (s[0] == '+' || s[0] == '-')) ? 1 : 0;
  std::size_t digits = 0;
  while (i < s.size() && isDigit(s[i])) ++i, ++digits;
  if (i < s.size() && s[i] == '.') {
    ++i;
    while (i < s.size() && isDigit(s[i])) ++i, ++digits;
  }
  return digits > 0 && i == s.size();
}
}  // namespace

Time parseSeconds(std::string_view token, const std::string& file, const std::string& record) {
  if (!isPlainDecimal(token)) {
    const double s = parseDouble(token, file, record);
    if (std::abs(s) > 9.0e9) fail(file, record, "time out of range: " + echo(token));
    return fromSeconds(s);
  }
  const bool negative = token.front() == '-';
  std::string_view s = (token.front() == '-' || token.front() == '+') ? token.substr(1) : token;
  const std::size_t dot = s.find('.');
  const std::string_view whole = s.substr(0, dot);
  const std::string_view frac = dot == std::string_view::npos ? std::string_view() : s.substr(dot + 1);
  if (whole.size() > 10) fail(file, record, "time out of range: " + echo(token));
  Time seconds = 0;
  for (char c : whole) seconds = seconds * 10 + (c - '0');
  if (seconds > 9'000'000'000) fail(file, record, "time out of range: " + echo(token));
  Time nanos = 0;
  for (std::size_t i = 0; i < 9; ++i) nanos = nanos * 10 + (i < frac.size() ? frac[i] - '0' : 0);
  if (frac.size() > 9 && frac[9] >= '5') ++nanos;  // round half up on the 10th decimal
  const Time t = seconds * kNanosPerSecond + nanos;
  return negative ? -t : t;
}

std::vector<double> parseDoubles(const std::vector<std::string_view>& fields, std::size_t first, std::size_t count,
                                 const std::string& file, const std::string& record) {
  std::vector<double> values;
  values.reserve(count);
  for (std::size_t i = first; i < first + count; ++i) values.push_back(parseDouble(fields.at(i), file, record));
  return values;
}

std::vector<Time> readTimesFile(const std::string& path) {
  std::vector<Time> times;
  for (const auto& line : readDataLines(path, "#")) {
    const std::string record = lineRecord(line.number);
    const auto f = splitWhitespace(line.text);
    requireColumns(f, 1, path, record);
    const Time t = parseSeconds(f[0], path, record);
    if (!times.empty()) requireIncreasingTime(times.back(), t, path, record);
    times.push_back(t);
  }
  return times;
}

Eigen::Matrix3d checkedRotation(const Eigen::Matrix3d& R, const std::string& file, const std::string& record) {
  const double err = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(err <= kRotationTolerance))
    fail(file, record, "rotation is not orthonormal (max |R^T R - I| = " + formatDouble(err) + ")");
  if (R.determinant() < 0) fail(file, record, "rotation has determinant < 0 (a reflection)");
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

Eigen::Quaterniond checkedQuaternion(double w, double x, double y, double z, const std::string& file,
                                     const std::string& record) {
  const Eigen::Quaterniond q(w, x, y, z);
  const double n = q.norm();
  if (!(std::abs(n - 1.0) <= kQuaternionTolerance))
    fail(file, record, "quaternion is not unit (|q| = " + formatDouble(n) + ")");
  return q.normalized();
}

void requireIncreasingTime(Time previous, Time t, const std::string& file, const std::string& record) {
  if (t == previous) fail(file, record, "duplicate timestamp " + formatSeconds(t) + " s");
  if (t < previous)
    fail(file, record,
         "timestamp goes backwards (" + formatSeconds(t) + " s after " + formatSeconds(previous) + " s)");
}

std::string staleStampNotice(Time previous, Time t, const std::string& file, const std::string& record) {
  if (t > previous) return "";
  const std::string where = file + (record.empty() ? "" : " (" + record + ")") + ": dropped: timestamp ";
  if (t == previous) return where + formatSeconds(t) + " s repeats the previous one";
  return where + "goes back to " + formatSeconds(t) + " s from " + formatSeconds(previous) + " s";
}

std::string formatDouble(double value) {
  char buf[64];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof(buf), value);
  return ec == std::errc() ? std::string(buf, ptr) : std::string("nan");
}

std::string formatNumberList(const std::vector<double>& values) {
  std::string s = "[";
  for (std::size_t i = 0; i < values.size(); ++i) s += (i ? ", " : "") + formatDouble(values[i]);
  return s + "]";
}

std::string formatRowMajor(const Eigen::Isometry3d& T) {
  std::vector<double> v;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) v.push_back(T.matrix()(r, c));
  return formatNumberList(v);
}

std::string formatSeconds(Time t) {
  const bool negative = t < 0;
  // Work on the magnitude in unsigned arithmetic so INT64_MIN cannot overflow.
  const std::uint64_t mag = negative ? 0 - static_cast<std::uint64_t>(t) : static_cast<std::uint64_t>(t);
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%s%llu.%09llu", negative ? "-" : "",
                static_cast<unsigned long long>(mag / 1'000'000'000ULL),
                static_cast<unsigned long long>(mag % 1'000'000'000ULL));
  return buf;
}

}  // namespace drover::io
