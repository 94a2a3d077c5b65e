#include "farfield/core/progress.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "farfield/core/log.h"

namespace farfield {

bool Progress::enabled() {
  const char* env = std::getenv("FF_PROGRESS");
  if (env && !std::strcmp(env, "0")) return false;
  return logLevel() <= LogLevel::Info;
}

Progress::Progress(std::string label, uint64_t total) : label_(std::move(label)), total_(total) {
  tty_ = isatty(fileno(stderr));
}

Progress::~Progress() { finish(); }

void Progress::advance(uint64_t steps) {
  const uint64_t done = done_.fetch_add(steps) + steps;
  print(done, false);
}

void Progress::finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (!enabled() || total_ == 0) return;
  std::fprintf(stderr, "%s%s: %llu/%llu (100%%) in %.1f s\n", tty_ ? "\r" : "", label_.c_str(),
               (unsigned long long)done_.load(), (unsigned long long)total_, clock_.seconds());
}

void Progress::print(uint64_t done, bool /*final*/) {
  if (!enabled() || total_ == 0) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  const double fraction = double(done) / double(total_);
  const double now = clock_.seconds();
  if (tty_) {
    if (now - last_draw_s_ < 0.1 && done < total_) return;
    last_draw_s_ = now;
    const int width = 30, filled = int(fraction * width + 0.5);
    std::fprintf(stderr, "\r%s [%.*s%*s] %llu/%llu %3.0f%% %.1f s", label_.c_str(), filled,
                 "==============================", width - filled, "", (unsigned long long)done,
                 (unsigned long long)total_, fraction * 100.0, now);
    std::fflush(stderr);
  } else {
    const int decile = int(fraction * 10.0);
    if (decile <= last_decile_ || decile >= 10) return;
    last_decile_ = decile;
    std::fprintf(stderr, "%s: %llu/%llu (%d%%) %.1f s\n", label_.c_str(), (unsigned long long)done,
                 (unsigned long long)total_, decile * 10, now);
  }
}

}  // namespace farfield
