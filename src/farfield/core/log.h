// Logging to stderr with levels. FF_LOG_LEVEL=debug|info|warn|error in the environment sets the threshold.
#pragma once

#include <sstream>
#include <string>

namespace farfield {

enum class LogLevel { Debug = 0, Info = 1, Warn = 2, Error = 3, Off = 4 };

LogLevel logLevel();
void setLogLevel(LogLevel level);
void logMessage(LogLevel level, const std::string& message);

}  // namespace farfield

#define FF_LOG(level, expr)                                                  \
  do {                                                                       \
    if (::farfield::logLevel() <= (level)) {                                 \
      std::ostringstream ff_log_stream_;                                     \
      ff_log_stream_ << expr;                                                \
      ::farfield::logMessage((level), ff_log_stream_.str());                 \
    }                                                                        \
  } while (0)
#define FF_DEBUG(expr) FF_LOG(::farfield::LogLevel::Debug, expr)
#define FF_INFO(expr) FF_LOG(::farfield::LogLevel::Info, expr)
#define FF_WARN(expr) FF_LOG(::farfield::LogLevel::Warn, expr)
