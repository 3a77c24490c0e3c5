// Camera sensor (EMVA 1288 linear model) and auto exposure; see camera_exposure.hpp for the model and its units.
#include "sim/camera_exposure.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "sim/camera_model.hpp"
#include "sim/gaussian_quantiles.hpp"
#include "sim/random.hpp"

namespace drover::sim {

namespace {

bool positiveFinite(double x) { return x > 0 && std::isfinite(x); }

// Below this mean the Poisson count is drawn exactly by inversion; above it as lambda + sqrt(lambda) z (the normal
// approximation, same mean and variance; the skew 1/sqrt(lambda) < 0.18 is invisible after the gain and rounding).
constexpr double kExactPoissonBelow = 32;

// Poisson(lambda) from one 64-bit hash: inversion of the CDF with a 32-bit uniform (the hash's top half) for small
// lambda, else the normal approximation with the Gaussian quantile of lane 0. Lanes 2-3 stay free for read noise.
double poissonCount(double lambda, std::uint64_t hash, const detail::GaussianQuantiles& normal) {
  if (lambda >= kExactPoissonBelow) return std::max(0.0, lambda + std::sqrt(lambda) * normal(hash, 0));
  const double u = (static_cast<double>(hash >> 32) + 0.5) * 0x1.0p-32;
  double p = std::exp(-lambda), cdf = p;
  int k = 0;
  while (u > cdf && k < 200) {  // P(k > 200 | lambda < 32) < 1e-80
    ++k;
    p *= lambda / k;
    cdf += p;
  }
  return k;
}

}  // namespace

std::string CameraExposureConfig::validate() const {
  std::ostringstream e;
  if (!positiveFinite(full_well_e)) {
    e << "camera full_well_e must be > 0 e-, got " << full_well_e;
  } else if (!(read_noise_e >= 0) || !std::isfinite(read_noise_e)) {
    e << "camera read_noise_e must be >= 0 e-, got " << read_noise_e;
  } else if (!positiveFinite(white_rate_e_per_s)) {
    e << "camera white_rate_e_per_s must be > 0 e-/s, got " << white_rate_e_per_s;
  } else if (!positiveFinite(min_exposure_s) || !positiveFinite(max_exposure_s) || min_exposure_s > max_exposure_s) {
    e << "camera exposure limits must satisfy 0 < min_exposure_s <= max_exposure_s, got " << min_exposure_s << ", "
      << max_exposure_s << " s";
  } else if (!(max_gain >= 1) || !std::isfinite(max_gain)) {
    e << "camera max_gain must be >= 1, got " << max_gain;
  } else if (!(fixed_gain >= 1) || !(fixed_gain <= max_gain)) {
    e << "camera fixed_gain must be in [1, max_gain = " << max_gain << "], got " << fixed_gain;
  } else if (!(target_grey > 0 && target_grey < 255)) {
    e << "camera target_grey must be in (0, 255) grey levels, got " << target_grey;
  } else if (!(deadband >= 0 && deadband < 1)) {
    e << "camera deadband must be in [0, 1), got " << deadband;
  } else if (!(damping > 0 && damping <= 1)) {
    e << "camera damping must be in (0, 1], got " << damping;
  } else if (!(max_step > 1) || !std::isfinite(max_step)) {
    e << "camera max_step must be > 1 and finite, got " << max_step;
  }
  return e.str();
}

// ---- sensor -------------------------------------------------------------------------------------------------

CameraSensor::CameraSensor(const CameraExposureConfig& config, bool noise)
    : config_(config), noise_(noise), electrons_per_grey_(config.full_well_e / 255.0) {}

double CameraSensor::electrons(double ideal, const ExposureSetting& s) const {
  return std::max(0.0, ideal) / 255.0 * config_.white_rate_e_per_s * s.exposure_s;
}

double CameraSensor::meanGrey(double ideal, const ExposureSetting& s) const {
  return std::min(255.0, std::min(electrons(ideal, s), config_.full_well_e) * s.gain / electrons_per_grey_);
}

double CameraSensor::noiseGrey(double ideal, const ExposureSetting& s) const {
  const double k = s.gain / electrons_per_grey_;  // [grey levels per e-]
  const double read2 = config_.read_noise_e * config_.read_noise_e;
  return std::sqrt(k * k * (electrons(ideal, s) + read2) + 1.0 / 12.0);
}

Image CameraSensor::expose(const RadianceImage& radiance, const ExposureSetting& s, std::uint64_t seed,
                           std::uint64_t frame_index) const {
  Image image;
  image.width = radiance.width;
  image.height = radiance.height;
  image.channels = radiance.channels;
  image.data.resize(radiance.grey.size());
  const detail::GaussianQuantiles& normal = detail::gaussianQuantiles();
  const double k = s.gain / electrons_per_grey_;
  const double to_electrons = config_.white_rate_e_per_s * s.exposure_s / 255.0;
  const std::size_t row_values = static_cast<std::size_t>(radiance.width) * static_cast<std::size_t>(radiance.channels);
  tbb::parallel_for(tbb::blocked_range<int>(0, radiance.height), [&](const tbb::blocked_range<int>& rows) {
    for (int v = rows.begin(); v != rows.end(); ++v) {
      for (std::size_t i = row_values * static_cast<std::size_t>(v), end = i + row_values; i < end; ++i) {
        const double lambda = std::max(0.0, static_cast<double>(radiance.grey[i])) * to_electrons;
        double charge = lambda, read = 0;
        if (noise_) {
          // i = pixel * channels + channel: one hash per pixel and channel.
          const std::uint64_t hash = hashKeys(seed, Stream::kCamera, frame_index, i, std::uint64_t{0xE5});
          charge = poissonCount(lambda, hash, normal);
          read = config_.read_noise_e * normal(hash, 2);
        }
        charge = std::min(charge, config_.full_well_e);  // the well saturates before the read-out
        image.data[i] = detail::quantiseGrey(static_cast<float>(k * (charge + read)));
      }
    }
  });
  return image;
}

// ---- auto exposure ------------------------------------------------------------------------------------------

AutoExposure::AutoExposure(const CameraExposureConfig& config, double initial_exposure_s, double rate_hz)
    : config_(config), max_exposure_s_(std::min(config.max_exposure_s, 0.9 / rate_hz)) {
  current_ = config_.auto_exposure ? split(initial_exposure_s)
                                   : ExposureSetting{initial_exposure_s, config_.fixed_gain};
}

ExposureSetting AutoExposure::split(double exposure_gain_s) const {
  const double min_exposure = std::min(config_.min_exposure_s, max_exposure_s_);
  const double product = std::clamp(exposure_gain_s, min_exposure, max_exposure_s_ * config_.max_gain);
  if (product <= max_exposure_s_) return {product, 1.0};
  return {max_exposure_s_, product / max_exposure_s_};
}

bool AutoExposure::atFloor() const {
  return current_.exposure_s >= max_exposure_s_ && current_.gain >= config_.max_gain * (1 - 1e-12);
}

void AutoExposure::update(double mean_grey) {
  if (!config_.auto_exposure) return;
  const double mean = std::max(mean_grey, 0.5);  // a black frame: step up by max_step
  if (std::abs(mean / config_.target_grey - 1.0) < config_.deadband) return;
  const double step =
      std::clamp(std::pow(config_.target_grey / mean, config_.damping), 1.0 / config_.max_step, config_.max_step);
  current_ = split(current_.exposure_s * current_.gain * step);
}

void AutoExposure::settle(const CameraSensor& sensor, const RadianceImage& radiance, int iterations) {
  // Every 4th pixel of every 4th row is plenty for a mean.
  const std::size_t channels = static_cast<std::size_t>(radiance.channels);
  for (int it = 0; it < iterations && config_.auto_exposure; ++it) {
    double sum = 0;
    std::size_t n = 0;
    for (int v = 0; v < radiance.height; v += 4)
      for (int u = 0; u < radiance.width; u += 4)
        for (std::size_t c = 0; c < channels; ++c, ++n)
          sum += sensor.meanGrey(radiance.grey[(static_cast<std::size_t>(v) * radiance.width + u) * channels + c],
                                 current_);
    if (n == 0) return;
    update(sum / static_cast<double>(n));
  }
}

double meanGrey(const Image& image) {
  if (image.data.empty()) return 0;
  double sum = 0;
  for (std::uint8_t p : image.data) sum += p;
  return sum / static_cast<double>(image.data.size());
}

}  // namespace drover::sim
