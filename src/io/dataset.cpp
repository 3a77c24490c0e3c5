#include "io/dataset.hpp"

#include <filesystem>
#include <stdexcept>

#include "io/bag_reader.hpp"
#include "io/error.hpp"
#include "io/euroc_reader.hpp"
#include "io/kitti_odometry.hpp"
#include "io/kitti_raw.hpp"
#include "io/sim_dataset.hpp"

namespace drover::io {

std::unique_ptr<Reader> openDataset(const std::string& path, const std::string& format,
                                    const DatasetOptions& options) {
  // The format is checked first so that a typo in it is reported as such, not as a missing dataset.
  const bool known = format == "kitti" || format == "kitti-raw" || format == "euroc" || format == "bag" ||
                     format == "sim";
  if (!known)
    throw std::invalid_argument("unknown dataset format '" + format + "' for " + path +
                                " (expected kitti, kitti-raw, euroc, bag or sim)");
  if (!std::filesystem::exists(path)) fail(path, "", "dataset not found");
  if (format == "euroc") return openEuroc(path, options);
  if (format == "kitti") return openKittiOdometry(path, options);
  if (format == "kitti-raw") return openKittiRaw(path, options);
  if (format == "sim") return openSimDataset(path, options);
  return openBag(path, options);
}

}  // namespace drover::io
