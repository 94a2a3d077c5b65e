// File helpers shared by the sources of the store's two databases (impostor_store.h, placement_store.h). Internal to
// the store module: only src/farfield/store/*.cpp include it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "farfield/impostor/impostor_mesh.h"

namespace farfield::store {

// ---- Paths and integrity primitives (store_integrity.cpp) ------------------------------------------------------

std::string joinPath(const std::string& dir, const std::string& relative);
// Calls the hook of setFileOperationHook, when one is set, before a file operation.
void fileOperation(const char* operation, const std::string& path);
// fsync of a file (or, with `directory`, of a directory), not reported to the hook.
void syncFile(const std::string& path, bool directory);
// fsync of a directory, reported to the hook ("sync-dir").
void syncDirectory(const std::string& dir);
// NAME.tmp, the temporary a write of NAME goes to.
std::string tempName(const std::string& path);
// fsync a finished temporary file and rename it over its target.
void commitTemp(const std::string& tmp, const std::string& path, bool sync_directory);
// The whole file, unchecked; errors name `record` when it is not empty.
std::string readWholeFile(const std::string& path, const std::string& record);
// Eight lower-case hex digits.
std::string hex32(uint32_t v);

// ---- The impostor mesh file (mesh_file_io.cpp) -----------------------------------------------------------------

// Parses and validates the bytes of a mesh file; errors name `file` and `record`.
impostor::DepthMeshImpostor meshFromBytes(const std::string& bytes, const std::string& file,
                                          const std::string& record);

// ---- The placement database (placed_impostor_io.cpp) -----------------------------------------------------------

inline constexpr char kImpostorDir[] = "impostors";  // DIR/impostors holds the layer files
// "impostor 12": how errors name an impostor's record.
std::string recordName(uint32_t id);
void createDirectory(const std::filesystem::path& dir);

}  // namespace farfield::store
