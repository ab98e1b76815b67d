#pragma once
// The web application's files as the ground station serves them: a URL prefix per folder, paths that
// stay inside their folder (no "..", no link out of it), content types by extension, and the files kept
// in memory once read (shared by every response; at most `cache_bytes` in all).

#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace tetra::ground {

struct StaticFile {
  std::shared_ptr<const std::string> content;
  std::string content_type;
};

class StaticFiles {
 public:
  explicit StaticFiles(std::size_t cache_bytes = 64U << 20) : cache_bytes_(cache_bytes) {}
  //! Serves `dir` under `prefix` ("/openmct/"); the longest matching prefix wins. False: no such folder.
  bool mount(const std::string& prefix, const std::string& dir);
  //! The file of a URL path ("/" is index.html); nullopt when there is none (or it lies outside).
  std::optional<StaticFile> get(const std::string& url_path);

 private:
  std::vector<std::pair<std::string, std::string>> mounts_;  //!< prefix, canonical folder
  std::size_t cache_bytes_;
  std::size_t cached_bytes_ = 0;
  std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const std::string>> cache_;
};

}  // namespace tetra::ground
