#pragma once
// The input queue of one live stage (pipeline::System): items in arrival order, blocking pop, and a bound on the
// items that may be dropped (sweeps, frames) while the others (IMU samples) are always kept: when a droppable item
// arrives and `limit` of them already wait, the oldest waiting one is dropped (LIO-SAM's queues drop nothing and
// fall behind; a robot would rather lose a sweep than its real time).
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <utility>

namespace drover::pipeline {

template <class Item>
class LiveQueue {
 public:
  // Returns true when an older droppable item was dropped to make room.
  bool push(Item item, bool droppable, std::size_t limit) {
    bool dropped = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (droppable && limit > 0 && droppable_ >= limit) {
        for (auto it = items_.begin(); it != items_.end(); ++it) {
          if (!it->second) continue;
          items_.erase(it);
          --droppable_;
          dropped = true;
          break;
        }
      }
      items_.emplace_back(std::move(item), droppable);
      droppable_ += droppable ? 1 : 0;
    }
    ready_.notify_one();
    return dropped;
  }

  // Blocks until an item is there (returned) or the queue is closed and empty (nullopt).
  std::optional<Item> pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait(lock, [this] { return !items_.empty() || closed_; });
    if (items_.empty()) return std::nullopt;
    std::pair<Item, bool> front = std::move(items_.front());
    items_.pop_front();
    droppable_ -= front.second ? 1 : 0;
    return std::move(front.first);
  }

  // No more pushes; pop() returns what is left, then nullopt.
  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
  }

  std::size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }
  std::size_t droppableWaiting() const {  // sweeps (frames) waiting
    std::lock_guard<std::mutex> lock(mutex_);
    return droppable_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<std::pair<Item, bool>> items_;
  std::size_t droppable_ = 0;
  bool closed_ = false;
};

}  // namespace drover::pipeline
