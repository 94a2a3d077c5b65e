// Numbers as text for reports and tables: one printf conversion of a double, and counts with thousands separators.
#pragma once

#include <cstdint>
#include <string>

namespace farfield {

// `format` holds one printf conversion of a double and any text around it ("%.2f", "%.1f ms", "%.2fx"); the result is
// cut at 63 characters.
std::string formatNumber(const char* format, double value);

// A count with a comma every three digits: 1234567 -> "1,234,567".
std::string thousands(uint64_t value);

}  // namespace farfield
