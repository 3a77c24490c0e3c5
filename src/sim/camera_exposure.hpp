#pragma once
// The simulated camera's sensor and auto exposure, as a machine-vision camera (global-shutter CMOS of a VIO rig)
// works, so that a dark scene is dark the way a night street is: the controller first lengthens the exposure, then
// raises the analogue gain, and when both are at their limits (the floor) the image gets darker and noisier.
//
// Sensor (EMVA 1288's linear model, Release 4.0, Sec. 2): a pixel collects mu_e = value * white_rate * t_exp
// photo-electrons, where value is the scene's linear value (1 = a white surface facing the sun in daylight,
// camera_model.hpp) = ideal grey / 255. The count is Poisson (shot noise, variance mu_e), clipped at the full well;
// read noise sigma_r [e-] adds before the gain; the ADC reads grey = gain * (n_e + read) / K with
// K = full_well / 255 [e- per grey level at unity gain], rounded and clipped to 8 bits. Predicted temporal noise
// [grey levels]: sigma_y^2 = (gain / K)^2 (mu_e + sigma_r^2) + 1/12 (EMVA 1288 Eq. 7 with the quantisation term).
//
// Auto exposure: after each frame the controller meters the frame's mean grey m and scales the product
// exposure * gain by (target / m)^damping, at most a factor max_step a frame, and holds inside a deadband (as camera
// AE loops do, to not hunt). Exposure is spent before gain (gain amplifies the read noise); the product is held in
// [min_exposure, max_exposure * max_gain]. The first frame starts settled (the camera ran before the recording).
//
// Noise is counter-based (seed, frame, pixel, channel), so a seed gives the same images for any thread count; the
// controller's state depends only on earlier frames, which the simulator renders in order.
#include <cstdint>
#include <string>

#include "types/camera.hpp"

namespace drover::sim {

struct RadianceImage;

struct CameraExposureConfig {
  bool enabled = true;               // false: the simulator uses the ideal camera (CameraRenderer::render)
  // Sensor. Defaults: a 6 ke- full-well global shutter pixel (e.g. a 1/3" VGA machine-vision sensor).
  double full_well_e = 6000;         // [e-] saturation charge; reads 255 at unity gain
  double read_noise_e = 4;           // [e- rms] temporal dark noise, before the gain
  // [e-/s] collected from a white surface facing the sun in daylight (scene value 1). 1e7 e-/s puts a daylight
  // scene (mean value ~0.4) at the target with ~0.6 ms at unity gain; the AE range (exposure 20 us .. 20 ms, gain
  // 1 .. 16) then spans 1/30 .. ~500x darker than daylight, so a night street (~1/1000 of daylight) is at the floor.
  double white_rate_e_per_s = 1e7;
  // Limits.
  double min_exposure_s = 20e-6;     // [s]
  double max_exposure_s = 0.02;      // [s] VIO cameras cap it to bound motion blur; used up to 0.9 / rate_hz
  double max_gain = 16;              // [x] analogue gain at most (24 dB); 1 = unity
  // Auto exposure.
  bool auto_exposure = true;         // false: fixed exposure (CameraModelConfig::exposure_s) and fixed_gain
  double fixed_gain = 1;             // [x] with auto_exposure off
  double target_grey = 100;          // [grey levels] the mean grey the controller aims for
  double deadband = 0.05;            // relative: no change while |mean / target - 1| < deadband
  double damping = 0.6;              // fraction of the log-brightness error corrected per frame, (0, 1]
  double max_step = 4;               // largest factor on exposure * gain per frame, > 1
  std::string validate() const;      // empty = valid, else names the bad value
};

struct ExposureSetting {
  double exposure_s = 0;  // [s]
  double gain = 1;        // [x]
};

// The sensor: radiance in, 8-bit image out. Pure (thread-safe).
class CameraSensor {
 public:
  // `noise` false: the mean electron count and no read noise (still clipped and quantised).
  CameraSensor(const CameraExposureConfig& config, bool noise);
  // Mean photo-electrons [e-] of a pixel with ideal grey `ideal` (255 * value) over the exposure.
  double electrons(double ideal, const ExposureSetting& s) const;
  // Noise-free output [grey levels, unquantised] (clipped at the full well and at 255).
  double meanGrey(double ideal, const ExposureSetting& s) const;
  // Predicted temporal noise [grey levels] (shot + read, gain, quantisation; no clipping): EMVA 1288 Eq. 7.
  double noiseGrey(double ideal, const ExposureSetting& s) const;
  // The 8-bit frame (mono or B, G, R as the radiance); rows in parallel.
  Image expose(const RadianceImage& radiance, const ExposureSetting& s, std::uint64_t seed,
               std::uint64_t frame_index) const;
  const CameraExposureConfig& config() const { return config_; }

 private:
  CameraExposureConfig config_;
  bool noise_;
  double electrons_per_grey_;  // K [e- per grey level at unity gain]
};

// The auto-exposure loop. Not thread-safe; one per camera stream.
class AutoExposure {
 public:
  // Starts at (initial_exposure_s, 1) clamped to the limits; with auto_exposure off it stays at
  // (initial_exposure_s, fixed_gain). The longest exposure is min(max_exposure_s, 0.9 / rate_hz): it must end
  // before the next frame starts.
  AutoExposure(const CameraExposureConfig& config, double initial_exposure_s, double rate_hz);
  const ExposureSetting& current() const { return current_; }
  bool atFloor() const;  // exposure and gain both at their maxima
  // Settles on a scene before the first frame: iterates update() on the noise-free mean the sensor would give.
  void settle(const CameraSensor& sensor, const RadianceImage& radiance, int iterations = 20);
  // One control step from the mean grey of the frame just taken.
  void update(double mean_grey);
  // exposure * gain split as the controller does (exposure first, then gain), clamped to the limits.
  ExposureSetting split(double exposure_gain_s) const;

 private:
  CameraExposureConfig config_;
  double max_exposure_s_;  // [s] the effective limit
  ExposureSetting current_;
};

// Mean grey of an 8-bit image over all pixels and channels.
double meanGrey(const Image& image);

}  // namespace drover::sim
