#pragma once
// The ground station's sessions (docs/ground.md, "Accounts"): a session id is 32 random bytes (64
// hexadecimal characters) with nothing inside it; the store keeps, per session, the keyed BLAKE2b of the
// id (never the id itself), its user and its expiry, in a journal file of its own (mode 0600) that every
// sign-in and sign-out appends to and fsyncs. A session therefore survives a restart, and a signed-out one
// never comes back before it expires: it is not in the store. Expired sessions are dropped when the journal
// is compacted (at open and whenever it holds more than twice the live sessions).

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "tetra/core/result.hpp"

namespace tetra::ground {

class SessionStore {
 public:
  //! Sessions held per user at once; a sign-in beyond this ends the user's session nearest to expiry.
  static constexpr std::size_t kSessionsPerUser = 64;

  //! Reads (or creates, mode 0600) the journal at `path`; `key` keys the stored hashes. An error names the
  //! file and line of a damaged entry, or a journal readable or writable by group or others.
  static Result<SessionStore> open(const std::string& path, const std::string& key, std::int64_t now_s);

  //! A new session id for `user`, valid until `now_s + lifetime_s` (UTC seconds), recorded in the journal.
  Result<std::string> issue(const std::string& user, std::int64_t now_s, std::int64_t lifetime_s);
  //! The user of a live session id (not expired, not signed out); another process's entries included.
  std::optional<std::string> user_of(const std::string& id, std::int64_t now_s);
  //! Ends the session (recorded in the journal); an unknown id is no error.
  Status revoke(const std::string& id);
  //! Live sessions in the store.
  std::size_t size() const { return live_.size(); }

 private:
  struct Entry {
    std::string user;
    std::int64_t expiry_s = 0;
  };
  SessionStore() = default;
  std::string hash_of(const std::string& id) const;
  Status load(std::int64_t now_s);
  Status append(const std::string& line);
  Status compact(std::int64_t now_s);
  void follow_file();

  std::string path_;
  std::string key_;
  std::map<std::string, Entry> live_;  //!< by the keyed hash of the id
  std::size_t journal_lines_ = 0;
  std::int64_t seen_size_ = -1;  //!< the journal's size and modification time when last read or written
  std::int64_t seen_mtime_ns_ = -1;
  std::int64_t now_s_ = 0;  //!< the newest time seen (expired entries are dropped on reading)
};

}  // namespace tetra::ground
