#include "farfield/store/generation_names.h"

#include <cstdio>

namespace farfield::store {

std::string generationPrefix(uint64_t generation) {
  if (generation == 0) return "";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "g%06llu.", static_cast<unsigned long long>(generation));
  return buf;
}

uint64_t generationOf(const std::string& name) {
  if (name.size() < 3 || name[0] != 'g') return 0;
  size_t k = 1;
  uint64_t g = 0;
  while (k < name.size() && name[k] >= '0' && name[k] <= '9' && k < 19) g = g * 10 + uint64_t(name[k++] - '0');
  return k >= 7 && k < name.size() && name[k] == '.' ? g : 0;
}

}  // namespace farfield::store
