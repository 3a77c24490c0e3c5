// Recognising a folder `drover sim` wrote, so that `--force` replaces only that (io/sim_dataset.hpp).
#include <filesystem>
#include <string>

#include "io/output_paths.hpp"
#include "io/sim_dataset.hpp"

namespace drover::io {
namespace {
namespace fs = std::filesystem;

// NNNNNN<extension>: a 6-digit index (simFileName).
bool isIndexedFile(const std::string& name, const std::string& extension) {
  return name.size() == 6 + extension.size() && name.compare(6, std::string::npos, extension) == 0 &&
         name.find_first_not_of("0123456789") == 6;
}

// "" when every entry of SUB (lidar/ or camera/) is timestamps.csv or NNNNNN<extension>.
std::string foreignEntry(const fs::path& sub, const std::string& extension) {
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(sub, ec)) {
    const std::string name = e.path().filename().string();
    if (name != "timestamps.csv" && !isIndexedFile(name, extension) && !isStagingLeftover(name))
      return (sub.filename() / name).string();
  }
  return ec ? sub.filename().string() + " (" + ec.message() + ")" : "";
}

}  // namespace

std::string simDatasetProblem(const fs::path& dir) {
  const std::string not_ours = ", which drover sim does not write";
  std::error_code ec;
  if (fs::is_empty(dir, ec) && !ec) return "";
  for (const char* file : {"calibration.yaml", "scenario.json", "groundtruth.txt", "imu.csv"})
    if (!fs::is_regular_file(fs::symlink_status(dir / file, ec)))
      return std::string("is not a complete simulated dataset (no ") + file + ")";
  for (const char* sub : {"lidar", "camera"})
    if (!fs::is_directory(fs::symlink_status(dir / sub, ec)) ||
        !fs::is_regular_file(fs::symlink_status(dir / sub / "timestamps.csv", ec)))
      return std::string("is not a complete simulated dataset (no ") + sub + "/timestamps.csv)";
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    const bool known = name == "calibration.yaml" || name == "scenario.json" || name == "groundtruth.txt" ||
                       name == "imu.csv" || name == "lidar" || name == "camera" || isStagingLeftover(name);
    if (!known) return "holds " + name + not_ours;
  }
  if (ec) return "cannot be listed: " + ec.message();
  for (const auto& [sub, extension] : {std::pair{"lidar", ".bin"}, std::pair{"camera", ".png"}})
    if (std::string name = foreignEntry(dir / sub, extension); !name.empty()) return "holds " + name + not_ours;
  return "";
}

}  // namespace drover::io
