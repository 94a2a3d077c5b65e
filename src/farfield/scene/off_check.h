// A strict check of an OFF file (Object File Format: "OFF", the vertex, face and edge counts, the vertices, then each
// face as its vertex count and indices) before assimp reads it. Debian's assimp 5.2 crashes on some damaged OFF files
// (a face line such as "3/1 4/4/1" read as indices, found by fuzz_assimp); Farfield refuses what the check does not
// accept, with an error naming the line, instead of handing it over.
#pragma once

#include <string>

namespace farfield::scene {

// Throws farfield::Error("PATH:LINE", reason) unless the file is a well-formed OFF file: the header (OFF, optionally
// with a prefix such as C, N or ST, and the counts on its line or the next), comment (#) and blank lines anywhere,
// vertex lines of at least three finite numbers, face lines of a count from 1 to 1,000 followed by that many
// integer indices below the vertex count (colour values may follow). Counts above 100 million are refused.
void checkOffFile(const std::string& path);

}  // namespace farfield::scene
