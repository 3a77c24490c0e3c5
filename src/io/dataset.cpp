#include "io/dataset.hpp"

#include <stdexcept>

namespace drover::io {

std::unique_ptr<Reader> openDataset(const std::string& path, const std::string& format, const DatasetOptions&) {
  throw std::invalid_argument("unknown dataset format '" + format + "' for " + path +
                              " (expected kitti, kitti-raw, euroc or bag)");
}

}  // namespace drover::io
