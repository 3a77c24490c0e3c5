// The Scan Context database: ring-key retrieval through the growing k-d tree finds the right place among many,
// never returns the most recent entries, narrows the shift search with a prior, and rejects bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "loop/scan_context_database.hpp"

namespace drover::loop {
namespace {

constexpr double kSector = 2 * std::numbers::pi / 60;

// A random "place": poles of random heights at random ranges and azimuths (seeded, so each id is reproducible).
lidar::PointCloud place(int seed) {
  std::mt19937 rng(static_cast<unsigned>(seed) * 7919u + 11u);
  std::uniform_real_distribution<double> range(3.0, 75.0), azimuth(0, 2 * std::numbers::pi), height(0.3, 6.0);
  lidar::PointCloud c;
  for (int k = 0; k < 80; ++k) {
    const double r = range(rng), a = azimuth(rng), h = height(rng);
    for (double z = 0; z <= h; z += 0.25)
      c.emplace_back(float(r * std::cos(a)), float(r * std::sin(a)), float(z - 2.0));
  }
  return c;
}

// The same place seen by a sensor turned by psi about z (p_B = Rz(-psi) p_A).
lidar::PointCloud turnedCloud(const lidar::PointCloud& a, double psi) {
  const Eigen::Matrix3f R = Eigen::AngleAxisf(float(-psi), Eigen::Vector3f::UnitZ()).toRotationMatrix();
  lidar::PointCloud b;
  for (const auto& p : a) b.push_back(R * p);
  return b;
}

ScanContextDatabaseConfig config(int exclude_recent) {
  ScanContextDatabaseConfig c;
  c.exclude_recent = exclude_recent;
  c.descriptor.lateral_steps = 0;  // the synthetic places are seen from the same point
  return c;
}

TEST(ScanContextDatabase, FindsTheRevisitedPlaceAmongTwoHundredWithItsShift) {
  ScanContextDatabase db(config(0));
  for (int id = 0; id < 200; ++id) db.add(id, makeScanContext(place(id), db.config().descriptor));
  EXPECT_EQ(db.searchable(), 200u);
  for (int id : {3, 77, 150}) {
    const double psi = (id % 13) * kSector;
    const AugmentedScanContext q = makeAugmentedScanContext(turnedCloud(place(id), psi), db.config().descriptor);
    const DatabaseQuery r = db.query(q);
    ASSERT_FALSE(r.candidates.empty());
    EXPECT_EQ(r.candidates[0].id, id);
    EXPECT_EQ(r.candidates[0].match.match.shift, id % 13);
    EXPECT_LT(r.candidates[0].match.match.distance, 1e-3);
    EXPECT_LE(r.candidates.size(), 10u);  // top-k by ring key, k = 10
    ASSERT_GT(r.candidates.size(), 1u);
    EXPECT_GT(r.candidates[1].match.match.distance, db.config().descriptor.threshold);  // others are not the place
  }
}

TEST(ScanContextDatabase, TheMostRecentEntriesAreNeverCandidates) {
  ScanContextDatabase db(config(5));
  const ScanContextConfig& d = db.config().descriptor;
  for (int id = 0; id < 5; ++id) db.add(id, makeScanContext(place(id), d));
  const AugmentedScanContext q = makeAugmentedScanContext(place(0), d);
  EXPECT_EQ(db.searchable(), 0u);
  EXPECT_TRUE(db.query(q).candidates.empty());  // entry 0 is the same place, but among the 5 newest
  db.add(5, makeScanContext(place(5), d));
  EXPECT_EQ(db.searchable(), 1u);
  const DatabaseQuery r = db.query(q);
  ASSERT_EQ(r.candidates.size(), 1u);
  EXPECT_EQ(r.candidates[0].id, 0);
  for (int id = 6; id < 40; ++id) db.add(id, makeScanContext(place(id), d));
  for (const LoopCandidate& c : db.query(q).candidates) EXPECT_LT(c.id, 35);  // the tree grows with the map
}

TEST(ScanContextDatabase, AYawPriorNarrowsEachCandidatesSearchToSevenShifts) {
  ScanContextDatabase db(config(0));
  for (int id = 0; id < 20; ++id) db.add(id, makeScanContext(place(id), db.config().descriptor));
  const double psi = 9 * kSector;
  const AugmentedScanContext q = makeAugmentedScanContext(turnedCloud(place(4), psi), db.config().descriptor);
  const DatabaseQuery full = db.query(q);
  const DatabaseQuery narrowed = db.query(q, [&](int) { return std::optional<double>(psi + 0.5 * kSector); });
  ASSERT_FALSE(narrowed.candidates.empty());
  EXPECT_EQ(narrowed.candidates[0].id, 4);
  EXPECT_EQ(narrowed.candidates[0].match.match.shift, 9);
  EXPECT_TRUE(narrowed.candidates[0].match.match.narrowed);
  EXPECT_EQ(narrowed.candidates[0].match.match.evaluated, 7);
  EXPECT_EQ(full.candidates[0].match.match.evaluated, 60);
  // Candidates that are other places fail the threshold in their window and fall back to the full search.
  for (std::size_t i = 1; i < narrowed.candidates.size(); ++i)
    EXPECT_TRUE(narrowed.candidates[i].match.match.fell_back);
}

TEST(ScanContextDatabase, APriorWithoutFallBackReachScoresOtherPlacesByTheirWindowOnly) {
  ScanContextDatabase db(config(0));
  for (int id = 0; id < 20; ++id) db.add(id, makeScanContext(place(id), db.config().descriptor));
  const double psi = 9 * kSector;
  const AugmentedScanContext q = makeAugmentedScanContext(turnedCloud(place(4), psi), db.config().descriptor);
  const DatabaseQuery r = db.query(q, [&](int) { return std::optional<YawPrior>(YawPrior(psi + 0.5 * kSector, 3)); });
  ASSERT_EQ(r.candidates.size(), 10u);
  EXPECT_EQ(r.candidates[0].id, 4);  // the revisit is still found, in its window
  EXPECT_EQ(r.candidates[0].match.match.shift, 9);
  EXPECT_EQ(r.shifts_evaluated, 10 * 7);  // no candidate paid for a fall-back
  for (std::size_t i = 1; i < r.candidates.size(); ++i) {
    EXPECT_FALSE(r.candidates[i].match.match.fell_back);
    EXPECT_GE(r.candidates[i].match.match.distance, db.config().descriptor.threshold);
  }
}

// Removal (a retired keyframe): an entry removed after it became searchable, and one removed while still among the
// newest, are never returned again; their descriptors are freed; the place a removed entry stood for is found in
// the entry that replaced it.
TEST(ScanContextDatabase, RemovedEntriesAreNeverCandidatesAgainAndTheirDescriptorsAreFreed) {
  ScanContextDatabase db(config(3));
  const ScanContextConfig& d = db.config().descriptor;
  for (int id = 0; id < 10; ++id) db.add(id, makeScanContext(place(id), d));
  const std::size_t bytes = db.descriptorBytes();
  db.remove(2);  // searchable already (entries 0..6 are)
  db.remove(8);  // still among the 3 newest
  db.remove(8);  // twice: harmless
  EXPECT_EQ(db.removed(), 2u);
  EXPECT_EQ(db.size(), 10u);
  EXPECT_LT(db.descriptorBytes(), bytes * 9 / 10);
  EXPECT_THROW(db.descriptor(2), std::invalid_argument);
  EXPECT_THROW(db.remove(99), std::invalid_argument);
  db.add(10, makeScanContext(place(2), d));  // the same place, seen again
  for (int id = 11; id < 15; ++id) db.add(id, makeScanContext(place(id), d));  // 8 and 10 become searchable
  for (int id : {2, 8}) {
    for (const LoopCandidate& c : db.query(makeAugmentedScanContext(place(id), d)).candidates) {
      EXPECT_NE(c.id, 2);
      EXPECT_NE(c.id, 8);
    }
  }
  const DatabaseQuery r = db.query(makeAugmentedScanContext(place(2), d));
  ASSERT_FALSE(r.candidates.empty());
  EXPECT_EQ(r.candidates[0].id, 10);
  EXPECT_LT(r.candidates[0].match.match.distance, 1e-3);
}

TEST(ScanContextDatabase, RejectsDescriptorsOfAnotherShapeDuplicateIdsAndBadConfigs) {
  ScanContextDatabase db(config(0));
  ScanContextConfig other = db.config().descriptor;
  other.sectors = 30;
  EXPECT_THROW(db.add(0, makeScanContext(place(0), other)), std::invalid_argument);
  db.add(1, makeScanContext(place(1), db.config().descriptor));
  EXPECT_THROW(db.add(1, makeScanContext(place(2), db.config().descriptor)), std::invalid_argument);
  EXPECT_THROW(db.descriptor(99), std::invalid_argument);
  EXPECT_THROW(db.query(makeAugmentedScanContext(place(0), other)), std::invalid_argument);
  ScanContextDatabaseConfig bad = config(0);
  bad.candidates = 0;
  EXPECT_THROW(ScanContextDatabase{bad}, std::invalid_argument);
  bad = config(-1);
  EXPECT_THROW(ScanContextDatabase{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace drover::loop
