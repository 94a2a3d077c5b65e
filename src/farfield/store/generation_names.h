// Generation-numbered file names shared by the store's databases (impostor_store.h, placement_store.h): a rewrite
// writes its data files under a new generation G ("gG.<rest>", G as six or more digits), so the files of the
// previous index stay untouched until the new index replaces it.
#pragma once

#include <cstdint>
#include <string>

namespace farfield::store {

// "g000007." for 7; "" for generation 0 (the names of version 1 and 2 stores).
std::string generationPrefix(uint64_t generation);
// The generation in a file name "gG.<rest>" (six or more digits); 0 when the name has none.
uint64_t generationOf(const std::string& name);

}  // namespace farfield::store
