#pragma once
// Files of the ground station that hold secrets, grant access or record it (accounts, the session key, the
// session journal, the audit file): written with mode 0600, and refused when group or others may read or
// write them.

#include <cstdint>
#include <string>

#include "tetra/core/result.hpp"

namespace tetra::ground {

//! Writes `text` to `path` with mode 0600: a new file beside it, fsynced and renamed over it. When `path`
//! is a symbolic link the file it points to is replaced (the link stays); a link to nothing is bad input
//! naming it (never replaced by a file, never followed to create one elsewhere).
Status write_private(const std::string& path, const std::string& text);
//! An error naming the file (`what` it is), its mode and `risk` (what others could do with it) when group
//! or others may read or write `path`; ok when it is private to its owner or absent.
Status check_private(const std::string& path, const std::string& what, const std::string& risk);

//! A file's size and modification time, to tell that another process changed it ({-1, -1}: absent).
struct FileStamp {
  std::int64_t size = -1;
  std::int64_t mtime_ns = -1;
  bool operator==(const FileStamp& other) const { return size == other.size && mtime_ns == other.mtime_ns; }
  bool operator!=(const FileStamp& other) const { return !(*this == other); }
};
FileStamp file_stamp(const std::string& path);

}  // namespace tetra::ground
