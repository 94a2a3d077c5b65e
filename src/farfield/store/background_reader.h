// Records of a database read on a background thread before the runtime needs them, under a byte budget of decoded
// bytes (DESIGN.md, "store": a paged reader with a byte budget). The reading itself is the caller's (a function from
// a key to a decoded value), so the cells of an impostor database (store/cell_reader.h) and the placed impostors of a
// placement (runtime/walkthrough_placed.cpp) share one reader: entering a cell or a problem view costs the upload and
// not the disk and the PNG decoding.
//
// The runtime asks for the keys it may need next (prefetch) and takes what it needs now (take). Prefetched values
// wait in memory under the byte budget, which holds at every moment: before a finished read is kept, the oldest
// waiting reads are dropped until it fits, and a value larger than the whole budget is not kept (the bytes of the one
// read in progress are counted when it finishes). A key taken before it was prefetched, or dropped, is read on the
// calling thread. Errors of a background read (a damaged file) are raised by take(), with the message the read
// function gave (file and record), never lost and never thrown on the reader thread.
//
// Thread safety: prefetch(), take() and takeIfReady() may be called from one thread (the render thread) while the
// reader runs; the read function must be safe to call from the reader thread and the caller's at once.
#pragma once

#include <algorithm>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>

#include "farfield/core/timer.h"

namespace farfield::store {

struct BackgroundReaderStats {
  size_t prefetch_requests = 0;  // keys queued
  size_t read_ahead = 0;         // values read by the background thread
  size_t taken_ready = 0;        // taken after their read had finished
  size_t taken_waited = 0;       // taken while being read (the caller waited for the rest)
  size_t taken_cold = 0;         // taken without a prefetch (read on the calling thread)
  size_t dropped = 0;            // prefetched values dropped for the budget
  size_t too_large = 0;          // of them, values larger than the whole budget (never kept)
  uint64_t held_bytes_max = 0;   // largest decoded bytes waiting at once
  double wait_ms_total = 0.0;    // time take() waited for a background read
};

template <class Value>
class BackgroundReader {
 public:
  using Read = std::function<Value(uint32_t key)>;         // throws farfield::Error for a damaged record
  using Bytes = std::function<uint64_t(const Value& value)>;  // decoded bytes the value holds

  BackgroundReader(Read read, Bytes bytes, uint64_t budget_bytes)
      : read_(std::move(read)), bytes_(std::move(bytes)), budget_bytes_(budget_bytes) {
    thread_ = std::thread([this] { run(); });
  }
  ~BackgroundReader() {  // stops the thread after its current read
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  BackgroundReader(const BackgroundReader&) = delete;
  BackgroundReader& operator=(const BackgroundReader&) = delete;

  // Queues a key for reading ahead; does nothing for a key that is waiting, queued or being read. Never blocks on
  // the disk. The caller checks that the key names a record.
  void prefetch(uint32_t key) {
    {
      std::lock_guard lock(mutex_);
      if (slots_.count(key) || std::find(queue_.begin(), queue_.end(), key) != queue_.end()) return;
      queue_.push_back(key);
      ++stats_.prefetch_requests;
    }
    wake_.notify_one();
  }

  // The key's value: a waiting one at once, one being read after its read, others read now on the calling thread.
  // Throws what the read threw. *how, when given: "ready", "waited" or "cold".
  std::shared_ptr<Value> take(uint32_t key, const char** how = nullptr) {
    std::unique_lock lock(mutex_);
    auto it = slots_.find(key);
    if (it != slots_.end()) {
      const char* kind = "ready";
      if (!it->second.done) {
        kind = "waited";
        Stopwatch wait;
        finished_.wait(lock, [&] {
          const auto s = slots_.find(key);
          return s == slots_.end() || s->second.done;
        });
        stats_.wait_ms_total += wait.milliseconds();
        it = slots_.find(key);
      }
      if (it != slots_.end()) {
        ++(kind[0] == 'r' ? stats_.taken_ready : stats_.taken_waited);
        if (how) *how = kind;
        return takeSlot(it);
      }
      // Finished and dropped for the budget while we waited: read it again below.
    }
    queue_.erase(std::remove(queue_.begin(), queue_.end(), key), queue_.end());
    ++stats_.taken_cold;
    lock.unlock();
    if (how) *how = "cold";
    return std::make_shared<Value>(read_(key));
  }

  // The key's value if its background read has finished (then as take() does: counted as ready, errors thrown),
  // else null: never waits and never reads.
  std::shared_ptr<Value> takeIfReady(uint32_t key) {
    std::lock_guard lock(mutex_);
    const auto it = slots_.find(key);
    if (it == slots_.end() || !it->second.done) return nullptr;
    ++stats_.taken_ready;
    return takeSlot(it);
  }

  // Forgets queued (not yet started) prefetches: the viewer turned elsewhere.
  void cancelQueued() {
    std::lock_guard lock(mutex_);
    queue_.clear();
  }

  BackgroundReaderStats stats() const {
    std::lock_guard lock(mutex_);
    return stats_;
  }
  uint64_t heldBytes() const {
    std::lock_guard lock(mutex_);
    return held_;
  }

 private:
  struct Slot {
    std::shared_ptr<Value> value;
    std::exception_ptr error;
    uint64_t bytes = 0;
    bool done = false;
    uint64_t order = 0;  // when it finished, for dropping the oldest
  };
  using Slots = std::map<uint32_t, Slot>;

  // With mutex_ held: the slot's value (or its error thrown), the slot forgotten.
  std::shared_ptr<Value> takeSlot(typename Slots::iterator it) {
    Slot slot = std::move(it->second);
    slots_.erase(it);
    held_ -= slot.bytes;
    if (slot.error) std::rethrow_exception(slot.error);
    return std::move(slot.value);
  }

  void run() {
    std::unique_lock lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return stop_ || !queue_.empty(); });
      if (stop_) return;
      const uint32_t key = queue_.front();
      queue_.pop_front();
      slots_[key];  // in flight
      lock.unlock();
      std::shared_ptr<Value> value;
      std::exception_ptr error;
      uint64_t bytes = 0;
      try {
        value = std::make_shared<Value>(read_(key));
        bytes = bytes_(*value);
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      ++stats_.read_ahead;
      // Room first, so that the waiting bytes stay under the budget at every moment: older reads are dropped, and a
      // value larger than the whole budget is not kept (take() reads it again).
      if (bytes > budget_bytes_) {
        slots_.erase(key);
        ++stats_.dropped;
        ++stats_.too_large;
        finished_.notify_all();
        continue;
      }
      makeRoom(bytes);
      Slot& slot = slots_[key];
      slot.value = std::move(value);
      slot.error = error;
      slot.bytes = bytes;
      slot.done = true;
      slot.order = ++finished_count_;
      held_ += bytes;
      stats_.held_bytes_max = std::max(stats_.held_bytes_max, held_);
      finished_.notify_all();
    }
  }

  // With mutex_ held: drops the oldest finished reads until `incoming` more bytes fit the budget (a failed read holds
  // no bytes and stays, so that take() can report it).
  void makeRoom(uint64_t incoming) {
    while (held_ + incoming > budget_bytes_) {
      auto oldest = slots_.end();
      for (auto it = slots_.begin(); it != slots_.end(); ++it)
        if (it->second.done && it->second.value && (oldest == slots_.end() || it->second.order < oldest->second.order))
          oldest = it;
      if (oldest == slots_.end()) return;
      held_ -= oldest->second.bytes;
      slots_.erase(oldest);
      ++stats_.dropped;
    }
  }

  Read read_;
  Bytes bytes_;
  uint64_t budget_bytes_;
  mutable std::mutex mutex_;
  std::condition_variable wake_, finished_;
  std::deque<uint32_t> queue_;
  Slots slots_;  // queued (not in slots_), in flight (done = false) or waiting (done = true)
  uint64_t held_ = 0;
  uint64_t finished_count_ = 0;
  bool stop_ = false;
  BackgroundReaderStats stats_;
  std::thread thread_;  // last: started once the members it uses are made
};

}  // namespace farfield::store
