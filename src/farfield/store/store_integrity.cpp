// Integrity of the store's files: CRC-32 checks, atomic writes (NAME.tmp, fsync, rename), directory syncs, whole-file
// reads, and the file operation hook through which the tests simulate crashes (impostor_store.h).
//
// Why CRC-32 per file and not per store: the runtime loads one view at a time inside a frame, so each file must be
// checkable alone, before it is parsed.
#include "farfield/store/impostor_store.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>

#include "farfield/core/error.h"
#include "farfield/store/store_files.h"

namespace fs = std::filesystem;

namespace farfield::store {

namespace {

std::function<void(const char*, const std::string&)>& fileHook() {
  static std::function<void(const char*, const std::string&)> hook;
  return hook;
}

[[noreturn]] void systemError(const std::string& path, const std::string& what, int error) {
  throw Error(path, what + ": " + std::strerror(error));
}

std::string parentDirectory(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? "." : parent.string();
}

}  // namespace

std::string joinPath(const std::string& dir, const std::string& relative) {
  return (fs::path(dir) / relative).string();
}

void fileOperation(const char* operation, const std::string& path) {
  if (fileHook()) fileHook()(operation, path);
}

void syncFile(const std::string& path, bool directory) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | (directory ? O_DIRECTORY : 0));
  if (fd < 0) systemError(path, "cannot open to sync", errno);
  if (::fsync(fd) != 0) {
    const int error = errno;
    ::close(fd);
    systemError(path, "fsync failed", error);
  }
  ::close(fd);
}

void syncDirectory(const std::string& dir) {
  fileOperation("sync-dir", dir);
  syncFile(dir, true);
}

std::string tempName(const std::string& path) { return path + ".tmp"; }

// fsync a finished temporary file and rename it over its target.
void commitTemp(const std::string& tmp, const std::string& path, bool sync_directory) {
  fileOperation("fsync", tmp);
  syncFile(tmp, false);
  fileOperation("rename", path);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) systemError(path, "cannot rename " + tmp + " over it", errno);
  if (sync_directory) syncDirectory(parentDirectory(path));
}

std::string readWholeFile(const std::string& path, const std::string& record) {
  const std::string prefix = record.empty() ? "" : record + ": ";
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) systemError(path, prefix + "cannot open", errno);
  std::string bytes;
  struct stat st {};
  if (::fstat(fd, &st) == 0 && st.st_size > 0) bytes.reserve(size_t(st.st_size));
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof(buffer));
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      ::close(fd);
      systemError(path, prefix + "read failed", error);
    }
    bytes.append(buffer, size_t(n));
  }
  ::close(fd);
  return bytes;
}

std::string hex32(uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof(buf), "%08x", v);
  return buf;
}

void syncCellFiles(const std::string& dir) {
  std::error_code ec;
  const fs::path cells = fs::path(dir) / "cells";
  if (fs::is_directory(cells, ec)) syncDirectory(cells.string());
  syncDirectory(dir);
}

FileCheck fileCheck(std::string_view bytes) {
  FileCheck check;
  check.bytes = bytes.size();
  check.crc32 = uint32_t(crc32_z(crc32_z(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(bytes.data()), bytes.size()));
  check.known = true;
  return check;
}

FileCheck writeFileAtomic(const std::string& path, std::string_view bytes, bool sync_directory) {
  const std::string tmp = tempName(path);
  fileOperation("create", tmp);
  struct Descriptor {
    int fd;
    ~Descriptor() {
      if (fd >= 0) ::close(fd);
    }
  } file{::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644)};
  if (file.fd < 0) systemError(tmp, "cannot open for writing", errno);
  const auto write_all = [&](std::string_view part) {
    while (!part.empty()) {
      const ssize_t n = ::write(file.fd, part.data(), part.size());
      if (n < 0) {
        if (errno == EINTR) continue;
        systemError(tmp, "write failed (disk full?)", errno);
      }
      part.remove_prefix(size_t(n));
    }
  };
  const size_t half = bytes.size() / 2;
  write_all(bytes.substr(0, half));
  fileOperation("write", tmp);  // a crash here leaves a torn temporary file, never a torn NAME
  write_all(bytes.substr(half));
  fileOperation("fsync", tmp);
  if (::fsync(file.fd) != 0) systemError(tmp, "fsync failed", errno);
  const int fd = file.fd;
  file.fd = -1;
  if (::close(fd) != 0) systemError(tmp, "write failed (close)", errno);
  fileOperation("rename", path);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) systemError(path, "cannot rename " + tmp + " over it", errno);
  if (sync_directory) syncDirectory(parentDirectory(path));
  return fileCheck(bytes);
}

std::string readCheckedFile(const std::string& path, const FileCheck& check, const std::string& record) {
  std::string bytes = readWholeFile(path, record);
  if (!check.known) return bytes;
  const std::string at = record.empty() ? "" : record + ": ";
  if (bytes.size() < check.bytes)
    throw Error(path, at + "truncated: " + std::to_string(bytes.size()) + " of " + std::to_string(check.bytes) +
                          " bytes");
  if (bytes.size() > check.bytes)
    throw Error(path, at + "too long: " + std::to_string(bytes.size()) + " bytes, the index says " +
                          std::to_string(check.bytes));
  const uint32_t crc = fileCheck(bytes).crc32;
  if (crc != check.crc32)
    throw Error(path, at + "checksum mismatch: CRC-32 " + hex32(crc) + ", the index says " + hex32(check.crc32));
  return bytes;
}

void setFileOperationHook(std::function<void(const char* operation, const std::string& path)> hook) {
  fileHook() = std::move(hook);
}

}  // namespace farfield::store
