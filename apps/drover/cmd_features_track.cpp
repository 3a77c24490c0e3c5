// drover features track: KLT tracking over a dataset's camera frames with a chosen detector; writes tracks.json
// (per frame and summary) and overlay PNGs.
#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "apps/drover/checked_options.hpp"
#include "apps/drover/commands.hpp"
#include "io/config.hpp"
#include "io/dataset.hpp"
#include "io/image_file_io.hpp"
#include "io/output_paths.hpp"
#include "io/trajectory_io.hpp"
#include "io/visual/visual_config_io.hpp"
#include "visual/detector_factory.hpp"
#include "visual/tracking_summary.hpp"

namespace drover::cli {

namespace {

using Json = nlohmann::ordered_json;

struct TrackOptions {
  std::string dataset, format, config, detector, out, weights;  // detector "" = the config's (else superpoint)
  int overlay_every = 0;
  int max_frames = 0;
  double start = 0, duration = 0;  // [s] from the first camera frame; duration 0 = to the end
  bool async = false;
  bool quiet = false;
};

Json frameJson(const visual::TrackingResult& r, Time t0) {
  return Json{{"t", static_cast<double>(r.t - t0) * 1e-9},  // [s] since the first camera frame
              {"stamp_ns", r.t},                            // the dataset's stamp
              {"features", r.features.size()},
              {"new", r.added},
              {"tracked", r.tracked},
              {"lost_flow", r.lost_flow},
              {"rejected_fb", r.rejected_fb},
              {"rejected_border", r.rejected_border},
              {"rejected_ransac", r.rejected_ransac},
              {"dropped_crowded", r.dropped_crowded},
              {"inlier_ratio", r.inlier_ratio},
              {"clahe", r.clahe_applied},
              {"ms", r.ms}};
}

Json summaryJson(const visual::TrackingSummary& s) {
  Json ended_by = Json::object();
  for (int c = 0; c < visual::kTrackEndCount; ++c)
    ended_by[visual::trackEndName(static_cast<visual::TrackEnd>(c))] = {
        {"tracks", s.ended_by[static_cast<std::size_t>(c)]},
        {"mean_length", s.mean_length_by[static_cast<std::size_t>(c)]}};
  return Json{{"frames", s.frames},
              {"mean_features", s.mean_features},
              {"mean_new", s.mean_new},
              {"mean_track_length", s.mean_track_length},
              {"finished_tracks", s.finished_tracks},
              {"mean_live_length", s.mean_live_length},
              {"ransac_inlier_ratio", s.mean_inlier_ratio},
              {"ms_per_frame", s.mean_ms},
              {"ms_p95", s.p95_ms},
              {"ms_max", s.max_ms},
              {"fraction_tracked_ge_50", s.fraction_tracked_ge_50},
              {"ended_by", ended_by}};
}

void runTrack(const TrackOptions& o) {
  io::checkOutputFolder(o.out, "--out");
  io::DatasetOptions options = o.config.empty() ? io::DatasetOptions{} : io::loadDatasetOptions(o.config);
  options.load_lidar = false;
  options.load_imu = false;
  options.load_images = true;
  if (o.max_frames > 0 && o.format == "kitti") options.kitti_max_frames = static_cast<std::size_t>(o.max_frames);
  const std::unique_ptr<io::Reader> reader = io::openDataset(o.dataset, o.format, options);
  // The config's visual.detector and visual.tracker sections, then the flags on top.
  const io::VisualConfig visual_config = o.config.empty() ? io::VisualConfig{} : io::loadVisualConfig(o.config);
  visual::DetectorConfig detector_config = visual_config.detector;
  if (!o.detector.empty()) detector_config.type = visual::parseDetectorType(o.detector);
  if (!o.weights.empty()) detector_config.superpoint.weights = o.weights;
  visual::FeatureTrackerConfig tracker_config = visual_config.tracker;
  if (o.async) tracker_config.async_detection = true;
  const visual::CameraModel camera(reader->calibration().camera);
  visual::FeatureTracker tracker(camera, visual::makeDetector(detector_config), tracker_config);

  std::filesystem::create_directories(o.out);
  visual::TrackingSummaryBuilder summary;
  Json frames = Json::array();
  Time t0 = -1;
  int index = 0;
  while (auto m = reader->next()) {
    const auto* frame = std::get_if<CameraFrame>(&*m);
    if (!frame) continue;
    if (t0 < 0) t0 = frame->t;
    const double since = static_cast<double>(frame->t - t0) * 1e-9;
    if (since < o.start) continue;
    if ((o.duration > 0 && since > o.start + o.duration) || (o.max_frames > 0 && index >= o.max_frames)) break;
    const CameraIntrinsics& k = camera.intrinsics();
    if (frame->image.width != k.width || frame->image.height != k.height)
      throw std::runtime_error(fmt::format("{}: image is {}x{} px but the camera calibration says {}x{} px",
                                           frame->source, frame->image.width, frame->image.height, k.width,
                                           k.height));
    const cv::Mat image = visual::imageView(frame->image);
    const visual::TrackingResult r = tracker.track(frame->t, image);
    summary.add(r);
    frames.push_back(frameJson(r, t0));
    if (o.overlay_every > 0 && index % o.overlay_every == 0)
      io::writeImage((std::filesystem::path(o.out) / fmt::format("overlay_{:06d}.png", index)).string(),
                     visual::drawTracks(image, r, camera.intrinsics().fx));
    ++index;
  }
  if (!o.quiet)
    for (const std::string& notice : reader->drops().notices) spdlog::warn("{}", notice);
  if (index == 0) throw std::runtime_error(o.dataset + ": no camera frames (in the --start/--duration window)");
  const visual::TrackingSummary s = summary.summary();
  const Json j{{"dataset", o.dataset},
               {"format", o.format},
               {"detector", visual::detectorTypeName(detector_config.type)},
               {"async", tracker_config.async_detection},
               {"max_features", tracker_config.max_features},
               {"summary", summaryJson(s)},
               {"frames", frames}};
  io::writeFileAtomically((std::filesystem::path(o.out) / "tracks.json").string(), j.dump(1) + "\n");
  if (!o.quiet)
    fmt::print(
        "{} frames, {:.1f} features/frame, mean track length {:.1f} frames ({} finished tracks), RANSAC "
        "inliers {:.3f}, {:.2f} ms/frame (p95 {:.2f}), {:.1f} % of frames with >= 50 tracked\n",
        s.frames, s.mean_features, s.mean_track_length, s.finished_tracks, s.mean_inlier_ratio, s.mean_ms, s.p95_ms,
        100 * s.fraction_tracked_ge_50);
}

}  // namespace

void registerFeaturesTrack(CLI::App& features) {
  auto* cmd = features.add_subcommand("track", "Track keypoints over a dataset's camera frames (KLT, VINS-Mono style)");
  auto o = std::make_shared<TrackOptions>();
  cmd->add_option("dataset", o->dataset, "Dataset folder or bag file")->required();
  cmd->add_option("--format", o->format, "Dataset format")
      ->required()
      ->check(CLI::IsMember({"kitti", "kitti-raw", "euroc", "bag", "sim"}));
  cmd->add_option("--config", o->config,
                  "Platform config (config/*.yaml): topics, calibration, visual.detector and visual.tracker");
  cmd->add_option("--detector", o->detector,
                  "Keypoint detector for new features (default: the config's, else superpoint)")
      ->check(CLI::IsMember({"superpoint", "shi-tomasi", "orb"}));
  cmd->add_option("--weights", o->weights, "SuperPoint ONNX file (default ../shared/models/superpoint_v1.onnx)");
  cmd->add_option("--out", o->out, "Output folder: tracks.json and overlay_NNNNNN.png")->required();
  addInteger(cmd, "--overlay-every", o->overlay_every, 0, 1'000'000'000,
             "Write an overlay PNG every N frames (0 = none)");
  addInteger(cmd, "--max-frames", o->max_frames, 1, 1'000'000'000, "Track at most N >= 1 frames (default: all)");
  addSeconds(cmd, "--start", o->start, atLeast(0, "s"), "Skip the first S seconds of camera frames");
  addSeconds(cmd, "--duration", o->duration, atLeast(0, "s"), "Track S seconds after --start (0 = to the end)");
  cmd->add_flag("--async", o->async,
                "Run the detector in a worker thread (results then depend on timing; overrides the config)");
  cmd->add_flag("-q,--quiet", o->quiet, "Print only errors");
  cmd->callback([o] { runTrack(*o); });
}

}  // namespace drover::cli
