#include "eval/stats.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace drover::eval {

double median(std::span<const double> values) {
  if (values.empty()) throw std::invalid_argument("median of an empty list");
  std::vector<double> v(values.begin(), values.end());
  const std::size_t mid = v.size() / 2;
  // nth_element is O(n); for an even count the lower middle value is the largest of the left part.
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  const double upper = v[mid];
  if (v.size() % 2 == 1) return upper;
  const double lower = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid));
  return 0.5 * (lower + upper);
}

ErrorStatistics computeStatistics(std::span<const double> errors) {
  if (errors.empty()) throw std::invalid_argument("statistics of an empty error list");
  ErrorStatistics s;
  s.count = errors.size();
  s.max = errors[0];
  s.min = errors[0];
  double sum = 0.0;
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < errors.size(); ++i) {
    const double e = errors[i];
    if (!std::isfinite(e)) throw std::invalid_argument("error " + std::to_string(i) + " is not finite");
    s.max = std::max(s.max, e);
    s.min = std::min(s.min, e);
    sum += e;
    sum_sq += e * e;
  }
  const double n = static_cast<double>(errors.size());
  s.mean = sum / n;
  s.sse = sum_sq;
  s.rmse = std::sqrt(sum_sq / n);
  // Two-pass variance: stable when the spread is small compared to the mean.
  double var = 0.0;
  for (const double e : errors) var += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(var / n);
  s.median = median(errors);
  return s;
}

}  // namespace drover::eval
