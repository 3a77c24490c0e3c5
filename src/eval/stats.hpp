#pragma once
// Summary statistics of a list of per-pose errors, defined exactly as evo's PE.get_all_statistics (numpy):
// std is the population standard deviation (ddof = 0), median is numpy's (mean of the two middle values for an
// even count), rmse = sqrt(mean(e^2)), sse = sum(e^2).
#include <cstddef>
#include <span>

namespace drover::eval {

struct ErrorStatistics {
  double max = 0.0;
  double min = 0.0;
  double std = 0.0;  // population standard deviation (ddof = 0)
  double median = 0.0;
  double mean = 0.0;
  double rmse = 0.0;
  double sse = 0.0;
  std::size_t count = 0;
};

// Throws std::invalid_argument for an empty list or a non-finite value (naming its index).
ErrorStatistics computeStatistics(std::span<const double> errors);

// numpy.median: the middle value, or the mean of the two middle values for an even count.
// Throws std::invalid_argument for an empty list.
double median(std::span<const double> values);

}  // namespace drover::eval
