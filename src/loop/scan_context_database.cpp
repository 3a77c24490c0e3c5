#include "loop/scan_context_database.hpp"

#include <algorithm>
#include <cstdint>
#include <map>
#include <nanoflann.hpp>
#include <stdexcept>
#include <unordered_map>

namespace drover::loop {
namespace {

// nanoflann's view of the ring keys: row i of `keys` is entry i's ring key.
struct RingKeyAdaptor {
  const std::vector<Eigen::VectorXf>* keys = nullptr;
  std::size_t kdtree_get_point_count() const { return keys->size(); }
  float kdtree_get_pt(std::uint32_t idx, std::size_t dim) const { return (*keys)[idx](static_cast<int>(dim)); }
  template <class BBox>
  bool kdtree_get_bbox(BBox& /*bb*/) const {
    return false;
  }
};

using RingKeyTree = nanoflann::KDTreeSingleIndexDynamicAdaptor<nanoflann::L2_Simple_Adaptor<float, RingKeyAdaptor>,
                                                               RingKeyAdaptor, -1, std::uint32_t>;

}  // namespace

std::string ScanContextDatabaseConfig::validate() const {
  if (std::string e = descriptor.validate(); !e.empty()) return "descriptor: " + e;
  if (candidates < 1) return "candidates must be >= 1";
  if (exclude_recent < 0) return "exclude_recent must be >= 0";
  return {};
}

struct ScanContextDatabase::Impl {
  std::vector<int> ids;                   // by entry
  std::vector<ScanContext> descriptors;   // by entry
  std::vector<Eigen::VectorXf> ring_keys; // by entry (the tree reads them)
  std::unordered_map<int, std::size_t> entry_of_id;
  RingKeyAdaptor adaptor;
  std::unique_ptr<RingKeyTree> tree;
  std::size_t indexed = 0;  // entries [0, indexed) are in the tree

  explicit Impl(int rings) : adaptor{&ring_keys} {
    tree = std::make_unique<RingKeyTree>(rings, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  }
};

ScanContextDatabase::ScanContextDatabase(const ScanContextDatabaseConfig& config) : config_(config) {
  if (std::string e = config.validate(); !e.empty()) throw std::invalid_argument("scan context database: " + e);
  impl_ = std::make_unique<Impl>(config.descriptor.rings);
}

ScanContextDatabase::~ScanContextDatabase() = default;
ScanContextDatabase::ScanContextDatabase(ScanContextDatabase&&) noexcept = default;
ScanContextDatabase& ScanContextDatabase::operator=(ScanContextDatabase&&) noexcept = default;

void ScanContextDatabase::add(int id, ScanContext descriptor) {
  if (descriptor.image.rows() != config_.descriptor.rings || descriptor.image.cols() != config_.descriptor.sectors)
    throw std::invalid_argument("scan context database: descriptor of entry " + std::to_string(id) + " is " +
                                std::to_string(descriptor.image.rows()) + "x" + std::to_string(descriptor.image.cols()) +
                                ", expected the config's rings x sectors");
  if (impl_->entry_of_id.count(id)) throw std::invalid_argument("scan context database: duplicate id " + std::to_string(id));
  Impl& m = *impl_;
  // The tree reads ring_keys through a pointer to the vector: growing it is fine, entries never move logically.
  m.entry_of_id[id] = m.ids.size();
  m.ids.push_back(id);
  m.ring_keys.push_back(descriptor.ring_key);
  m.descriptors.push_back(std::move(descriptor));
  // Entries older than the exclusion window become searchable.
  const std::size_t ready = m.ids.size() > static_cast<std::size_t>(config_.exclude_recent)
                                ? m.ids.size() - static_cast<std::size_t>(config_.exclude_recent)
                                : 0;
  if (ready > m.indexed) {
    m.tree->addPoints(static_cast<std::uint32_t>(m.indexed), static_cast<std::uint32_t>(ready - 1));
    m.indexed = ready;
  }
}

DatabaseQuery ScanContextDatabase::query(const AugmentedScanContext& q,
                                         const std::function<std::optional<double>(int)>& yaw_prior) const {
  DatabaseQuery out;
  const Impl& m = *impl_;
  out.searchable = static_cast<int>(m.indexed);
  if (m.indexed == 0 || q.descriptors.empty()) return out;
  for (const ScanContext& d : q.descriptors)
    if (d.ring_key.size() != config_.descriptor.rings)
      throw std::invalid_argument("scan context database: query ring key size differs from the config's rings");

  // Union of each virtual position's top-k by ring key, keeping the smallest ring-key distance per entry.
  std::map<std::uint32_t, float> retrieved;
  const std::size_t k = std::min<std::size_t>(static_cast<std::size_t>(config_.candidates), m.indexed);
  std::vector<std::uint32_t> idx(k);
  std::vector<float> d2(k);
  for (const ScanContext& d : q.descriptors) {
    nanoflann::KNNResultSet<float, std::uint32_t> result(k);
    result.init(idx.data(), d2.data());
    m.tree->findNeighbors(result, d.ring_key.data(), nanoflann::SearchParams());
    for (std::size_t i = 0; i < result.size(); ++i) {
      auto [it, inserted] = retrieved.emplace(idx[i], d2[i]);
      if (!inserted) it->second = std::min(it->second, d2[i]);
    }
  }
  for (const auto& [entry, dist2] : retrieved) {
    LoopCandidate c;
    c.id = m.ids[entry];
    c.ring_key_distance = std::sqrt(static_cast<double>(dist2));
    const std::optional<double> prior = yaw_prior ? yaw_prior(c.id) : std::nullopt;
    c.match = augmentedShiftSearch(m.descriptors[entry], q, prior, config_.descriptor);
    out.shifts_evaluated += c.match.match.evaluated;
    out.candidates.push_back(c);
  }
  std::stable_sort(out.candidates.begin(), out.candidates.end(), [](const LoopCandidate& a, const LoopCandidate& b) {
    return a.match.match.distance < b.match.match.distance;
  });
  return out;
}

std::size_t ScanContextDatabase::size() const { return impl_->ids.size(); }
std::size_t ScanContextDatabase::searchable() const { return impl_->indexed; }

const ScanContext& ScanContextDatabase::descriptor(int id) const {
  auto it = impl_->entry_of_id.find(id);
  if (it == impl_->entry_of_id.end()) throw std::invalid_argument("scan context database: unknown id " + std::to_string(id));
  return impl_->descriptors[it->second];
}

}  // namespace drover::loop
