// The bakes' concurrency: one producer on the calling thread (the one with the OpenGL context: captures, PVS
// sampling) and CPU workers on the other cores (mesh construction, files), with a bounded queue between them.
//
// Why a producer/consumer instead of a parallel loop: the GL work needs the one context, which is current on one
// thread only, while the constructions are pure CPU work without shared state. A tbb::concurrent_bounded_queue
// bounds the jobs in flight (each holds full-resolution images) and lets the GL thread block when the workers fall
// behind instead of rendering ahead without limit. The queue carries a null job per worker to stop them.
#pragma once

#include <oneapi/tbb/concurrent_queue.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "farfield/core/progress.h"

namespace farfield::bake {

// Worker threads for an option value: n > 0 as given, 0 = hardware threads - 1, at least 1.
inline size_t workerCount(int option) {
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  return option > 0 ? size_t(option) : size_t(std::max(1u, hw - 1));
}

// Calls produce(push) on this thread; each job it pushes is handed to consume(job) on one of `workers` threads.
// push() blocks while `capacity` jobs wait and returns false once a consumer has failed (the producer should stop).
// After produce returns (or throws), the workers finish the queued jobs and are joined; then the producer's
// exception, else the first consumer's, is rethrown. With a progress label, a bar advances per consumed job.
template <class Job>
void produceAndConsume(size_t workers, size_t capacity, const std::string& progress_label, size_t total,
                       const std::function<void(const std::function<bool(std::shared_ptr<Job>)>&)>& produce,
                       const std::function<void(Job&)>& consume) {
  tbb::concurrent_bounded_queue<std::shared_ptr<Job>> queue;
  queue.set_capacity(std::ptrdiff_t(std::max<size_t>(1, capacity)));
  std::mutex error_mutex;
  std::exception_ptr worker_error;
  std::atomic<bool> failed{false};
  std::unique_ptr<Progress> progress;
  if (!progress_label.empty()) progress = std::make_unique<Progress>(progress_label, total);

  auto work = [&] {
    for (;;) {
      std::shared_ptr<Job> job;
      queue.pop(job);
      if (!job) return;
      if (failed.load()) continue;  // drain without work after an error
      try {
        consume(*job);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!worker_error) worker_error = std::current_exception();
        failed = true;
      }
      if (progress) progress->advance();
    }
  };
  std::vector<std::thread> pool;
  std::exception_ptr producer_error;
  {
    // Whatever happens on this thread, the workers are stopped and joined before leaving.
    struct Joiner {
      tbb::concurrent_bounded_queue<std::shared_ptr<Job>>& queue;
      std::vector<std::thread>& pool;
      ~Joiner() {
        for (size_t i = 0; i < pool.size(); ++i) queue.push(nullptr);
        for (std::thread& t : pool) t.join();
      }
    } joiner{queue, pool};
    for (size_t w = 0; w < std::max<size_t>(1, workers); ++w) pool.emplace_back(work);
    try {
      produce([&](std::shared_ptr<Job> job) {
        if (failed.load()) return false;
        queue.push(std::move(job));
        return true;
      });
    } catch (...) {
      producer_error = std::current_exception();
      failed = true;
    }
  }
  if (progress) progress->finish();
  if (producer_error) std::rethrow_exception(producer_error);
  if (worker_error) std::rethrow_exception(worker_error);
}

}  // namespace farfield::bake
