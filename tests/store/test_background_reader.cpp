// The background reader (store/background_reader.h) as the placed walkthrough uses it: takeIfReady() gives a value
// only once its background read has finished, never waits and never reads; an error of the read is raised by it; and
// a value is read once however often it is queued.
#include "farfield/store/background_reader.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "farfield/core/error.h"

namespace farfield::store {
namespace {

// A read function held at a gate until the test opens it, counting its calls.
struct GatedRead {
  std::mutex mutex;
  std::condition_variable opened_cv;
  bool opened = false;
  std::atomic<int> calls{0};
  void open() {
    {
      std::lock_guard lock(mutex);
      opened = true;
    }
    opened_cv.notify_all();
  }
  int read(uint32_t key) {
    ++calls;
    std::unique_lock lock(mutex);
    opened_cv.wait(lock, [&] { return opened; });
    if (key == 13) throw Error("record 13", "damaged");
    return int(key) * 10;
  }
};

template <class Reader>
void waitForReads(const Reader& reader, size_t n) {
  for (int i = 0; i < 5000 && reader.stats().read_ahead < n; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ASSERT_EQ(reader.stats().read_ahead, n);
}

TEST(BackgroundReaderTest, TakeIfReadyGivesOnlyFinishedReadsAndNeverReads) {
  GatedRead gate;
  BackgroundReader<int> reader([&](uint32_t key) { return gate.read(key); }, [](const int&) { return uint64_t(4); },
                               1024);
  EXPECT_EQ(reader.takeIfReady(7), nullptr);  // never queued: not read here
  reader.prefetch(7);
  reader.prefetch(7);  // queued once
  for (int i = 0; i < 5000 && gate.calls == 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_EQ(gate.calls, 1);
  EXPECT_EQ(reader.takeIfReady(7), nullptr);  // being read: no wait
  gate.open();
  waitForReads(reader, 1);
  const std::shared_ptr<int> value = reader.takeIfReady(7);
  ASSERT_NE(value, nullptr);
  EXPECT_EQ(*value, 70);
  EXPECT_EQ(reader.takeIfReady(7), nullptr);  // taken: gone
  EXPECT_EQ(gate.calls, 1);
  EXPECT_EQ(reader.heldBytes(), 0u);
  const BackgroundReaderStats stats = reader.stats();
  EXPECT_EQ(stats.taken_ready, 1u);
  EXPECT_EQ(stats.taken_cold, 0u);
  EXPECT_EQ(stats.prefetch_requests, 1u);
  EXPECT_EQ(stats.held_bytes_max, 4u);
}

TEST(BackgroundReaderTest, AnErrorOfABackgroundReadIsRaisedByTakeIfReady) {
  GatedRead gate;
  gate.open();
  BackgroundReader<int> reader([&](uint32_t key) { return gate.read(key); }, [](const int&) { return uint64_t(4); },
                               1024);
  reader.prefetch(13);
  waitForReads(reader, 1);
  try {
    reader.takeIfReady(13);
    FAIL() << "no error raised";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("record 13"), std::string::npos) << e.what();
  }
  // Taken with its error: a take() now reads it on the calling thread, and raises again.
  EXPECT_THROW(reader.take(13), Error);
  EXPECT_EQ(gate.calls, 2);
}

}  // namespace
}  // namespace farfield::store
