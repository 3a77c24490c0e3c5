#include "loop/place_recognition_eval.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

namespace drover::loop {

PrCounts countAt(const std::vector<PlaceQuery>& queries, double threshold) {
  if (!std::isfinite(threshold)) throw std::invalid_argument(fmt::format("threshold {} is not finite", threshold));
  PrCounts c;
  c.threshold = threshold;
  c.queries = queries.size();
  for (const PlaceQuery& q : queries) {
    const bool detected = q.has_candidate && q.distance < threshold;
    const bool tp = detected && q.candidate_correct;
    if (q.has_true_revisit) ++c.true_revisits;
    if (tp) ++c.tp;
    if (detected && !tp) ++c.fp;
    if (q.has_true_revisit && !tp) ++c.fn;
    if (!q.has_true_revisit && !detected) ++c.tn;
  }
  const double tp = static_cast<double>(c.tp);
  if (c.tp + c.fp > 0) c.precision = tp / static_cast<double>(c.tp + c.fp);
  if (c.tp + c.fn > 0) c.recall = tp / static_cast<double>(c.tp + c.fn);
  if (c.precision + c.recall > 0) c.f1 = 2 * c.precision * c.recall / (c.precision + c.recall);
  return c;
}

std::vector<PrCounts> precisionRecallCurve(const std::vector<PlaceQuery>& queries,
                                           const std::vector<double>& thresholds) {
  std::vector<PrCounts> out;
  out.reserve(thresholds.size());
  for (double t : thresholds) out.push_back(countAt(queries, t));
  return out;
}

std::vector<double> thresholdRange(double first, double last, double step) {
  if (!std::isfinite(first) || !std::isfinite(last) || !std::isfinite(step) || step <= 0 || last < first)
    throw std::invalid_argument(fmt::format("threshold range {} .. {} step {} is invalid", first, last, step));
  std::vector<double> out;
  // Multiples of step from first (no accumulated rounding), the last one kept within step / 1000 of `last`.
  for (long i = 0;; ++i) {
    const double t = first + static_cast<double>(i) * step;
    if (t > last + step * 1e-3) break;
    out.push_back(t);
  }
  return out;
}

std::string TruthConfig::validate() const {
  if (!std::isfinite(true_distance) || true_distance <= 0) return "true_distance must be finite and > 0 m";
  if (!std::isfinite(correct_distance) || correct_distance <= 0) return "correct_distance must be finite and > 0 m";
  if (exclude_recent < 0) return "exclude_recent must be >= 0";
  if (!std::isfinite(min_age) || min_age < 0) return "min_age must be finite and >= 0 s";
  return {};
}

std::size_t eligibleEnd(const std::vector<Time>& times, std::size_t query, const TruthConfig& config) {
  if (std::string e = config.validate(); !e.empty()) throw std::invalid_argument("truth config: " + e);
  if (query >= times.size())
    throw std::invalid_argument(fmt::format("query {} out of range ({} keyframes)", query, times.size()));
  const std::size_t recent = static_cast<std::size_t>(config.exclude_recent);
  std::size_t end = query > recent ? query - recent : 0;
  const Time newest = times[query] - fromSeconds(config.min_age);
  while (end > 0 && times[end - 1] > newest) --end;
  return end;
}

TruthMatch matchAgainstTruth(const std::vector<Eigen::Vector3d>& positions, const std::vector<Time>& times,
                             std::size_t query, std::ptrdiff_t candidate, const TruthConfig& config) {
  if (positions.size() != times.size())
    throw std::invalid_argument(fmt::format("{} positions for {} times", positions.size(), times.size()));
  const std::size_t end = eligibleEnd(times, query, config);
  TruthMatch m;
  for (std::size_t i = 0; i < end; ++i) {
    const double d = (positions[i] - positions[query]).norm();
    if (m.nearest < 0 || d < m.nearest_distance) {
      m.nearest = static_cast<std::ptrdiff_t>(i);
      m.nearest_distance = d;
    }
  }
  m.has_true_revisit = m.nearest >= 0 && m.nearest_distance <= config.true_distance;
  if (candidate >= 0) {
    if (static_cast<std::size_t>(candidate) >= positions.size())
      throw std::invalid_argument(fmt::format("candidate {} out of range ({} keyframes)", candidate, positions.size()));
    m.candidate_distance = (positions[static_cast<std::size_t>(candidate)] - positions[query]).norm();
    m.candidate_correct = m.candidate_distance <= config.correct_distance;
  }
  return m;
}

}  // namespace drover::loop
