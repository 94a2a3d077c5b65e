#include "farfield/core/log.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace farfield {
namespace {

LogLevel levelFromEnvironment() {
  const char* env = std::getenv("FF_LOG_LEVEL");
  if (!env) return LogLevel::Info;
  if (!std::strcmp(env, "debug")) return LogLevel::Debug;
  if (!std::strcmp(env, "warn")) return LogLevel::Warn;
  if (!std::strcmp(env, "error")) return LogLevel::Error;
  if (!std::strcmp(env, "off")) return LogLevel::Off;
  return LogLevel::Info;
}

std::atomic<LogLevel>& currentLevel() {
  static std::atomic<LogLevel> level{levelFromEnvironment()};
  return level;
}

}  // namespace

LogLevel logLevel() { return currentLevel().load(std::memory_order_relaxed); }
void setLogLevel(LogLevel level) { currentLevel().store(level); }

void logMessage(LogLevel level, const std::string& message) {
  static std::mutex mutex;
  static const char* const names[] = {"debug", "info", "warn", "error"};
  std::lock_guard<std::mutex> lock(mutex);
  std::fprintf(stderr, "[%s] %s\n", names[int(level) < 4 ? int(level) : 3], message.c_str());
}

}  // namespace farfield
