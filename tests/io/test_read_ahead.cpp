// io::readAhead hands out the inner reader's stream unchanged: the same measurements in the same order, its drops
// as they happened, its error at the position it was thrown, and the end for good; it never hangs when dropped
// half way.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "io/error.hpp"
#include "io/read_ahead.hpp"

namespace drover::io {
namespace {

// Measurement k is an IMU sample at k ns; every `drop_every`-th one is dropped with a notice instead; at `fail_at`
// next() throws an IoError naming the record.
class CountingReader final : public Reader {
 public:
  CountingReader(std::size_t count, std::size_t drop_every, std::size_t fail_at, std::atomic<std::size_t>* reads)
      : count_(count), drop_every_(drop_every), fail_at_(fail_at), reads_(reads) {}
  std::optional<Measurement> next() override {
    for (;;) {
      if (reads_ != nullptr) ++*reads_;
      if (k_ == fail_at_) throw IoError("imu.csv", "line " + std::to_string(k_), "not a number");
      if (k_ >= count_) return std::nullopt;
      const std::size_t k = k_++;
      if (drop_every_ > 0 && k % drop_every_ == drop_every_ - 1) {
        dropMeasurement("imu.csv (line " + std::to_string(k) + "): stamp does not advance");
        continue;
      }
      ImuSample s;
      s.t = static_cast<Time>(k);
      return s;
    }
  }
  const Calibration& calibration() const override { return calibration_; }
  const GroundTruth& groundTruth() const override { return truth_; }
  std::string describe() const override { return "counting"; }

 private:
  std::size_t count_, drop_every_, fail_at_, k_ = 0;
  std::atomic<std::size_t>* reads_;
  Calibration calibration_;
  GroundTruth truth_;
};

constexpr std::size_t kNever = static_cast<std::size_t>(-1);

TEST(ReadAhead, HandsOutTheInnerStreamWithItsDropsAsTheyHappened) {
  CountingReader plain(5000, 7, kNever, nullptr);
  const std::unique_ptr<Reader> ahead = readAhead(std::make_unique<CountingReader>(5000, 7, kNever, nullptr), 3);
  EXPECT_EQ(ahead->describe(), "counting");
  std::size_t n = 0;
  for (;;) {
    const std::optional<Measurement> a = plain.next();
    const std::optional<Measurement> b = ahead->next();
    ASSERT_EQ(a.has_value(), b.has_value()) << "at " << n;
    ASSERT_EQ(ahead->drops().measurements, plain.drops().measurements) << "at " << n;
    ASSERT_EQ(ahead->drops().notices, plain.drops().notices);
    if (!a) break;
    ASSERT_EQ(std::get<ImuSample>(*a).t, std::get<ImuSample>(*b).t);
    ++n;
  }
  EXPECT_EQ(n, 5000u - 5000u / 7);
  EXPECT_EQ(ahead->drops().notices.size(), ReaderDrops::kMaxNotices) << "the inner reader's limit, kept";
  EXPECT_FALSE(ahead->next()) << "the end stays the end";
  EXPECT_EQ(ahead->drops().measurements, plain.drops().measurements) << "its drops are not counted twice";
}

TEST(ReadAhead, RethrowsTheInnerReadersErrorAfterTheMeasurementsReadBeforeIt) {
  const std::unique_ptr<Reader> ahead = readAhead(std::make_unique<CountingReader>(100, 0, 40, nullptr), 8);
  for (Time k = 0; k < 40; ++k) ASSERT_EQ(std::get<ImuSample>(*ahead->next()).t, k);
  for (int again = 0; again < 2; ++again) {
    try {
      ahead->next();
      FAIL() << "expected the inner reader's error";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find("imu.csv (line 40)"), std::string::npos) << e.what();
    }
  }
}

TEST(ReadAhead, ReadsNoFurtherAheadThanItsCapacityAndStopsWhenDroppedHalfWay) {
  std::atomic<std::size_t> reads{0};
  {
    const std::unique_ptr<Reader> ahead = readAhead(std::make_unique<CountingReader>(1000000, 0, kNever, &reads), 16);
    ASSERT_TRUE(ahead->next());
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (reads < 18 && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    EXPECT_EQ(reads.load(), 1u + 16u + 1u) << "one handed out, 16 queued, one read waiting for room";
  }  // destroyed with a full queue and the worker waiting: must join, not hang
  EXPECT_EQ(reads.load(), 18u);
}

TEST(ReadAhead, RefusesAZeroCapacityAndNoReader) {
  EXPECT_THROW(readAhead(std::make_unique<CountingReader>(1, 0, kNever, nullptr), 0), std::invalid_argument);
  EXPECT_THROW(readAhead(nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace drover::io
