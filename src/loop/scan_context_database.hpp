#pragma once
// The place-recognition database of Scan Context (Kim & Kim, IROS 2018, Sec. IV): every keyframe's descriptor,
// with its ring key indexed in a k-d tree (nanoflann) that grows with the map. A query retrieves the top-k
// keyframes by ring-key distance (rotation invariant), excluding the most recent ones (they are trivially
// similar), and ranks them by the column distance of Eq. 5-6 found by the shift search: the prior-narrowed search
// (Drover's paper, Eqs. 2-4) when the caller gives a yaw prior for the candidate, else the full search.
//
// Query descriptors may be laterally augmented (Scan Context++ root shifting, see scan_context.hpp): each
// virtual position's ring key retrieves its own top-k; of their union the top-k by ring-key distance are scored,
// each with the real position and the virtual position that retrieved it, and the better of the two is kept.
//
// Entries become searchable only once `exclude_recent` newer entries exist (the reference implementation's
// NUM_EXCLUDE_RECENT), so the tree never holds an entry a query may not return. Not thread-safe.
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "loop/scan_context.hpp"

namespace drover::loop {

struct ScanContextDatabaseConfig {
  ScanContextConfig descriptor;
  int candidates = 10;           // [-] top-k keyframes by ring-key distance per query descriptor (reference: 10)
  int exclude_recent = 50;       // [entries] the newest entries are never candidates (reference: 50 keyframes)
  std::string validate() const;  // empty when valid
};

struct LoopCandidate {
  int id = -1;                   // the database entry's id (a keyframe index)
  double ring_key_distance = 0;  // [-] L2 distance of the ring keys that retrieved it
  AugmentedMatch match;          // column distance, shift, yaw [rad] and the query's virtual position
};

struct DatabaseQuery {
  std::vector<LoopCandidate> candidates;  // scored, best (lowest distance) first
  int searchable = 0;                     // entries in the tree at query time
  int shifts_evaluated = 0;               // column-distance evaluations over all candidates
};

class ScanContextDatabase {
 public:
  // Throws std::invalid_argument when config.validate() fails.
  explicit ScanContextDatabase(const ScanContextDatabaseConfig& config = {});
  ~ScanContextDatabase();
  ScanContextDatabase(ScanContextDatabase&&) noexcept;
  ScanContextDatabase& operator=(ScanContextDatabase&&) noexcept;

  // Stores a keyframe's (non-augmented) descriptor under `id`. Throws std::invalid_argument when its shape is not
  // the config's.
  void add(int id, ScanContext descriptor);

  // Candidates for the query (descriptors[0] = the real sensor position). yaw_prior(id), when given and returning a
  // value, is the expected yaw [rad] of the query relative to entry `id` (p_entry = Rz(yaw) p_query), e.g. from the
  // current trajectory estimate: it narrows that candidate's shift search to +-search_radius sectors, with the
  // fall-back the YawPrior allows (a plain yaw: the full search).
  DatabaseQuery query(const AugmentedScanContext& query,
                      const std::function<std::optional<YawPrior>(int id)>& yaw_prior = {}) const;

  // Drops entry `id` for good (its keyframe's clouds were retired, a newer keyframe stands for the place): it is
  // never a candidate again and its descriptor is freed. Removing twice is harmless; an unknown id throws
  // std::invalid_argument.
  void remove(int id);
  std::size_t size() const;                     // entries stored, removed ones included
  std::size_t removed() const;                  // entries removed
  std::size_t searchable() const;               // entries old enough to be returned
  const ScanContext& descriptor(int id) const;  // throws std::invalid_argument for an unknown or removed id
  std::size_t descriptorBytes() const;          // [bytes] the stored descriptors' matrices and ring keys
  const ScanContextDatabaseConfig& config() const { return config_; }

 private:
  struct Impl;
  ScanContextDatabaseConfig config_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drover::loop
