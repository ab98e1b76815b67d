#include "tetra/ground/session_store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <sstream>
#include <vector>

#include "tetra/core/csv.hpp"
#include "tetra/ground/operators.hpp"
#include "tetra/ground/private_file.hpp"

namespace tetra::ground {

namespace {

constexpr const char* kHeader =
    "# tetra ground sessions: + HASH EXPIRY_S USER | - HASH (a journal; do not edit)\n";

bool is_hex(const std::string& text, std::size_t size) {
  return text.size() == size && text.find_first_not_of("0123456789abcdef") == std::string::npos;
}

bool is_count(const std::string& text) {
  return !text.empty() && text.size() <= 18 && text.find_first_not_of("0123456789") == std::string::npos;
}

}  // namespace

Result<SessionStore> SessionStore::open(const std::string& path, const std::string& key, std::int64_t now_s) {
  // It holds keyed hashes of the session ids, never an id: reading it signs no one in, writing it does (a
  // line giving one's own session another user).
  if (auto s = check_private(path, "the session journal", "whoever writes it can sign in as any operator");
      !s)
    return s.error();
  SessionStore store;
  store.path_ = path;
  store.key_ = key;
  if (auto s = store.load(now_s); !s) return s.error();
  if (auto s = store.compact(now_s); !s) return s.error();
  return store;
}

std::string SessionStore::hash_of(const std::string& id) const {
  return keyed_hash_hex(key_, "session:" + id);
}

Status SessionStore::load(std::int64_t now_s) {
  now_s_ = std::max(now_s_, now_s);
  live_.clear();
  journal_lines_ = 0;
  const FileStamp stamp = file_stamp(path_);
  if (stamp.size < 0) {
    seen_size_ = -1;
    seen_mtime_ns_ = -1;
    return ok_status();
  }
  auto text = read_text_file(path_);
  if (!text) return text.error();
  // A last line without its newline is an append cut short (power loss): it never took effect.
  const std::size_t complete = text->rfind('\n') == std::string::npos ? 0 : text->rfind('\n') + 1;
  std::istringstream in(text->substr(0, complete));
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    ++journal_lines_;
    std::istringstream fields(line);
    std::string op, hash, expiry, user, extra;
    fields >> op >> hash;
    const std::string where = path_ + ":" + std::to_string(number);
    if (op == "+" && (fields >> expiry >> user) && !(fields >> extra) && is_hex(hash, 64) &&
        is_count(expiry) && valid_user_name(user).ok()) {
      const std::int64_t expiry_s = std::stoll(expiry);
      if (expiry_s >= now_s_) live_[hash] = {user, expiry_s};
    } else if (op == "-" && !(fields >> extra) && is_hex(hash, 64)) {
      live_.erase(hash);
    } else {
      return bad_input(where +
                       ": expected '+ HASH EXPIRY_S USER' or '- HASH' (the session journal is damaged; "
                       "removing the file signs every operator out)");
    }
  }
  seen_size_ = stamp.size;
  seen_mtime_ns_ = stamp.mtime_ns;
  return ok_status();
}

void SessionStore::follow_file() {
  const FileStamp stamp = file_stamp(path_);
  if (stamp.size == seen_size_ && stamp.mtime_ns == seen_mtime_ns_) return;
  // Changed by another process (or removed): read again; unreadable means no sessions (refuse, not guess).
  if (!load(now_s_)) live_.clear();
}

Status SessionStore::append(const std::string& line) {
  const int fd = ::open(path_.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0) return failure(path_ + ": cannot write the session journal");
  const bool written =
      ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size()) && ::fsync(fd) == 0;
  ::close(fd);
  if (!written) return failure(path_ + ": cannot write the session journal");
  ++journal_lines_;
  const FileStamp stamp = file_stamp(path_);
  seen_size_ = stamp.size;
  seen_mtime_ns_ = stamp.mtime_ns;
  return ok_status();
}

Status SessionStore::compact(std::int64_t now_s) {
  std::string text = kHeader;
  for (auto it = live_.begin(); it != live_.end();) {
    if (it->second.expiry_s < now_s) {
      it = live_.erase(it);
      continue;
    }
    text += "+ " + it->first + " " + std::to_string(it->second.expiry_s) + " " + it->second.user + "\n";
    ++it;
  }
  if (auto s = write_private(path_, text); !s) return s;
  journal_lines_ = live_.size();
  const FileStamp stamp = file_stamp(path_);
  seen_size_ = stamp.size;
  seen_mtime_ns_ = stamp.mtime_ns;
  return ok_status();
}

Result<std::string> SessionStore::issue(const std::string& user, std::int64_t now_s,
                                        std::int64_t lifetime_s) {
  now_s_ = std::max(now_s_, now_s);
  follow_file();
  std::vector<std::map<std::string, Entry>::iterator> own;
  for (auto it = live_.begin(); it != live_.end(); ++it) {
    if (it->second.user == user) own.push_back(it);
  }
  if (own.size() >= kSessionsPerUser) {
    auto oldest = own.front();
    for (auto it : own) {
      if (it->second.expiry_s < oldest->second.expiry_s) oldest = it;
    }
    const std::string hash = oldest->first;
    live_.erase(oldest);
    if (auto s = append("- " + hash + "\n"); !s) return s.error();
  }
  const std::string id = random_hex(32);
  const std::string hash = hash_of(id);
  const std::int64_t expiry_s = now_s + lifetime_s;
  if (auto s = append("+ " + hash + " " + std::to_string(expiry_s) + " " + user + "\n"); !s) return s.error();
  live_[hash] = {user, expiry_s};
  if (journal_lines_ > 2 * live_.size() + 256) {
    if (auto s = compact(now_s_); !s) return s.error();
  }
  return id;
}

std::optional<std::string> SessionStore::user_of(const std::string& id, std::int64_t now_s) {
  if (!is_hex(id, 64)) return std::nullopt;
  now_s_ = std::max(now_s_, now_s);
  follow_file();
  const auto it = live_.find(hash_of(id));
  if (it == live_.end() || it->second.expiry_s < now_s) return std::nullopt;
  return it->second.user;
}

Status SessionStore::revoke(const std::string& id) {
  if (!is_hex(id, 64)) return ok_status();
  follow_file();
  const std::string hash = hash_of(id);
  if (live_.erase(hash) == 0) return ok_status();
  return append("- " + hash + "\n");
}

}  // namespace tetra::ground
