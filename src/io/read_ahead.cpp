#include "io/read_ahead.hpp"

#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace drover::io {
namespace {

class ReadAheadReader final : public Reader {
 public:
  ReadAheadReader(std::unique_ptr<Reader> inner, std::size_t capacity)
      : inner_(std::move(inner)), capacity_(capacity) {
    if (!inner_) throw std::invalid_argument("readAhead: no reader");
    if (capacity_ == 0) throw std::invalid_argument("readAhead: capacity must be >= 1");
    worker_ = std::thread([this] { work(); });
  }

  ~ReadAheadReader() override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    worker_.join();
  }

  std::optional<Measurement> next() override {
    Item item;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [this] { return !queue_.empty(); });
      Item& front = queue_.front();
      if (front.measurement) {
        item = std::move(front);
        queue_.pop_front();
      } else {  // the end or an error stays queued, its drops taken once: every later call answers the same
        item.error = front.error;
        item.drops = std::exchange(front.drops, 0);
        item.notices = std::move(front.notices);
        front.notices.clear();
      }
    }
    changed_.notify_all();
    // Past the inner reader's notice limit the empty notices are not stored (the limits are the same).
    for (std::size_t k = 0; k < item.drops; ++k)
      dropMeasurement(k < item.notices.size() ? std::move(item.notices[k]) : std::string());
    if (item.error) std::rethrow_exception(item.error);
    return std::move(item.measurement);
  }

  const Calibration& calibration() const override { return inner_->calibration(); }
  const GroundTruth& groundTruth() const override { return inner_->groundTruth(); }
  std::string describe() const override { return inner_->describe(); }

 private:
  struct Item {
    std::optional<Measurement> measurement;  // nullopt with no error: the end
    std::exception_ptr error;
    std::size_t drops = 0;              // measurements the inner reader dropped before this one
    std::vector<std::string> notices;   // their notices (fewer once the inner reader stops keeping them)
  };

  void work() {
    std::size_t dropped = 0, noticed = 0;
    for (;;) {
      Item item;
      try {
        item.measurement = inner_->next();
      } catch (...) {
        item.error = std::current_exception();
      }
      const ReaderDrops& d = inner_->drops();
      item.drops = d.measurements - dropped;
      item.notices.assign(d.notices.begin() + static_cast<std::ptrdiff_t>(noticed), d.notices.end());
      dropped = d.measurements;
      noticed = d.notices.size();
      const bool last = !item.measurement;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [this] { return stop_ || queue_.size() < capacity_; });
        if (stop_) return;
        queue_.push_back(std::move(item));
      }
      changed_.notify_all();
      if (last) return;
    }
  }

  std::unique_ptr<Reader> inner_;
  const std::size_t capacity_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Item> queue_;
  bool stop_ = false;
  std::thread worker_;  // last: started once everything it uses exists
};

}  // namespace

std::unique_ptr<Reader> readAhead(std::unique_ptr<Reader> inner, std::size_t capacity) {
  return std::make_unique<ReadAheadReader>(std::move(inner), capacity);
}

}  // namespace drover::io
