#include "tetra/ground/static_files.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace tetra::ground {

namespace {

namespace fs = std::filesystem;

std::string content_type_of(const fs::path& path) {
  static const std::map<std::string, std::string> types{{".html", "text/html; charset=utf-8"},
                                                        {".js", "text/javascript; charset=utf-8"},
                                                        {".css", "text/css; charset=utf-8"},
                                                        {".json", "application/json"},
                                                        {".map", "application/json"},
                                                        {".png", "image/png"},
                                                        {".svg", "image/svg+xml"},
                                                        {".ico", "image/x-icon"},
                                                        {".woff", "font/woff"},
                                                        {".woff2", "font/woff2"},
                                                        {".ttf", "font/ttf"},
                                                        {".txt", "text/plain; charset=utf-8"}};
  const auto it = types.find(path.extension().string());
  return it == types.end() ? "application/octet-stream" : it->second;
}

bool inside(const fs::path& file, const std::string& dir) {
  const std::string f = file.string();
  return f.size() > dir.size() && f.compare(0, dir.size(), dir) == 0 && f[dir.size()] == '/';
}

}  // namespace

bool StaticFiles::mount(const std::string& prefix, const std::string& dir) {
  std::error_code ec;
  const fs::path canonical = fs::canonical(dir, ec);
  if (ec || !fs::is_directory(canonical)) return false;
  mounts_.emplace_back(prefix, canonical.string());
  std::sort(mounts_.begin(), mounts_.end(),
            [](const auto& a, const auto& b) { return a.first.size() > b.first.size(); });
  return true;
}

std::optional<StaticFile> StaticFiles::get(const std::string& url_path) {
  for (const auto& [prefix, dir] : mounts_) {
    if (url_path.compare(0, prefix.size(), prefix) != 0) continue;
    std::string rest = url_path.substr(prefix.size());
    if (rest.empty() || rest.back() == '/') rest += "index.html";
    if (rest.find("..") != std::string::npos || rest[0] == '/') return std::nullopt;
    std::error_code ec;
    const fs::path file = fs::canonical(fs::path(dir) / rest, ec);  // links resolved: must stay inside
    if (ec || !inside(file, dir) || !fs::is_regular_file(file, ec)) return std::nullopt;
    const std::string key = file.string();
    {
      const std::lock_guard lock(mutex_);
      const auto it = cache_.find(key);
      if (it != cache_.end()) return StaticFile{it->second, content_type_of(file)};
    }
    std::ifstream in(file, std::ios::binary);
    if (!in) return std::nullopt;
    std::ostringstream text;
    text << in.rdbuf();
    auto content = std::make_shared<const std::string>(text.str());
    const std::lock_guard lock(mutex_);
    if (cached_bytes_ + content->size() <= cache_bytes_ && cache_.emplace(key, content).second)
      cached_bytes_ += content->size();
    return StaticFile{content, content_type_of(file)};
  }
  return std::nullopt;
}

}  // namespace tetra::ground
