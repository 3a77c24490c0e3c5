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
  std::vector<int> ids;                    // by entry
  std::vector<ScanContext> descriptors;    // by entry
  std::vector<Eigen::VectorXf> ring_keys;  // by entry (the tree reads them)
  std::vector<bool> removed;               // by entry
  std::size_t removed_count = 0;
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
                                std::to_string(descriptor.image.rows()) + "x" +
                                std::to_string(descriptor.image.cols()) + ", expected the config's rings x sectors");
  if (impl_->entry_of_id.count(id))
    throw std::invalid_argument("scan context database: duplicate id " + std::to_string(id));
  Impl& m = *impl_;
  // The tree reads ring_keys through a pointer to the vector: growing it is fine, entries never move logically.
  m.entry_of_id[id] = m.ids.size();
  m.ids.push_back(id);
  m.ring_keys.push_back(descriptor.ring_key);
  m.descriptors.push_back(std::move(descriptor));
  m.removed.push_back(false);
  // Entries older than the exclusion window become searchable.
  const std::size_t ready = m.ids.size() > static_cast<std::size_t>(config_.exclude_recent)
                                ? m.ids.size() - static_cast<std::size_t>(config_.exclude_recent)
                                : 0;
  if (ready > m.indexed) {
    m.tree->addPoints(static_cast<std::uint32_t>(m.indexed), static_cast<std::uint32_t>(ready - 1));
    for (std::size_t e = m.indexed; e < ready; ++e)  // removed before they became searchable
      if (m.removed[e]) m.tree->removePoint(e);
    m.indexed = ready;
  }
}

DatabaseQuery ScanContextDatabase::query(const AugmentedScanContext& q,
                                         const std::function<std::optional<YawPrior>(int)>& yaw_prior) const {
  DatabaseQuery out;
  const Impl& m = *impl_;
  out.searchable = static_cast<int>(m.indexed);
  if (m.indexed == 0 || q.descriptors.empty()) return out;
  for (const ScanContext& d : q.descriptors)
    if (d.ring_key.size() != config_.descriptor.rings)
      throw std::invalid_argument("scan context database: query ring key size differs from the config's rings");

  // Each virtual position's top-k by ring key; an entry retrieved by several keeps its smallest ring-key distance
  // and the position that gave it. The best `candidates` entries overall are then scored, each with the real
  // position's descriptor and the one that retrieved it (scoring every entry against every position costs 9x).
  struct Retrieved {
    float d2;
    std::size_t position;
  };
  std::map<std::uint32_t, Retrieved> retrieved;
  const std::size_t k = std::min<std::size_t>(static_cast<std::size_t>(config_.candidates), m.indexed);
  std::vector<std::uint32_t> idx(k);
  std::vector<float> d2(k);
  for (std::size_t v = 0; v < q.descriptors.size(); ++v) {
    nanoflann::KNNResultSet<float, std::uint32_t> result(k);
    result.init(idx.data(), d2.data());
    m.tree->findNeighbors(result, q.descriptors[v].ring_key.data(), nanoflann::SearchParams());
    for (std::size_t i = 0; i < result.size(); ++i) {
      auto [it, inserted] = retrieved.emplace(idx[i], Retrieved{d2[i], v});
      if (!inserted && d2[i] < it->second.d2) it->second = {d2[i], v};
    }
  }
  std::vector<std::pair<std::uint32_t, Retrieved>> ranked(retrieved.begin(), retrieved.end());
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const auto& a, const auto& b) { return a.second.d2 < b.second.d2; });
  if (ranked.size() > k) ranked.resize(k);
  for (const auto& [entry, r] : ranked) {
    LoopCandidate c;
    c.id = m.ids[entry];
    c.ring_key_distance = std::sqrt(static_cast<double>(r.d2));
    const std::optional<YawPrior> prior = yaw_prior ? yaw_prior(c.id) : std::nullopt;
    // The real position, and the virtual one that retrieved the entry when that is another; the better is kept.
    const auto offset = [&](std::size_t v) { return q.offsets.size() > v ? q.offsets[v] : Eigen::Vector2f::Zero(); };
    const ScanContext& entry_descriptor = m.descriptors[entry];
    c.match = {narrowedShiftSearch(entry_descriptor, q.descriptors[0], prior, config_.descriptor), 0, offset(0)};
    if (r.position != 0) {
      const ShiftMatch v = narrowedShiftSearch(entry_descriptor, q.descriptors[r.position], prior, config_.descriptor);
      if (v.distance < c.match.match.distance) c.match = {v, static_cast<int>(r.position), offset(r.position)};
    }
    out.shifts_evaluated += c.match.match.evaluated;
    out.candidates.push_back(c);
  }
  std::stable_sort(out.candidates.begin(), out.candidates.end(), [](const LoopCandidate& a, const LoopCandidate& b) {
    return a.match.match.distance < b.match.match.distance;
  });
  return out;
}

void ScanContextDatabase::remove(int id) {
  Impl& m = *impl_;
  const auto it = m.entry_of_id.find(id);
  if (it == m.entry_of_id.end())
    throw std::invalid_argument("scan context database: cannot remove unknown id " + std::to_string(id));
  const std::size_t e = it->second;
  if (m.removed[e]) return;
  m.removed[e] = true;
  ++m.removed_count;
  m.descriptors[e] = ScanContext{};  // the ring key stays: the tree reads it when it rebuilds its sub-trees
  if (e < m.indexed) m.tree->removePoint(e);
}

std::size_t ScanContextDatabase::removed() const { return impl_->removed_count; }

std::size_t ScanContextDatabase::descriptorBytes() const {
  std::size_t bytes = 0;
  for (const ScanContext& d : impl_->descriptors)
    bytes += sizeof(float) * static_cast<std::size_t>(d.image.size() + d.occupied.size() + d.ring_key.size() +
                                                      d.sector_key.size() + d.unit_columns.size() +
                                                      d.column_norms.size());
  return bytes;
}

std::size_t ScanContextDatabase::size() const { return impl_->ids.size(); }
std::size_t ScanContextDatabase::searchable() const { return impl_->indexed; }

const ScanContext& ScanContextDatabase::descriptor(int id) const {
  auto it = impl_->entry_of_id.find(id);
  if (it == impl_->entry_of_id.end())
    throw std::invalid_argument("scan context database: unknown id " + std::to_string(id));
  if (impl_->removed[it->second])
    throw std::invalid_argument("scan context database: id " + std::to_string(id) + " was removed");
  return impl_->descriptors[it->second];
}

}  // namespace drover::loop
