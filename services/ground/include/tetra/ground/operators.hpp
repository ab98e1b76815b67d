#pragma once
// Operator accounts of the ground station (docs/ground.md, "Accounts"): a file of `user:role:hash` lines,
// the hash argon2id (libsodium's crypto_pwhash_str, memory-hard), managed by `tetra ground passwd`; and
// sessions as opaque random ids kept in a journal of the ground's (session_store.hpp), so a session
// survives a restart and a signed-out one stays out. A session's user and role are looked up, never read
// from the id: the role is read from the accounts file at each request, so a changed role or a removed
// account takes effect at once.

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/ground/private_file.hpp"
#include "tetra/ground/session_store.hpp"

namespace tetra::ground {

enum class Role { kViewer, kCommander };
const char* to_string(Role role);
std::optional<Role> role_named(const std::string& name);

struct Account {
  std::string user;
  Role role = Role::kViewer;
  std::string hash;  //!< argon2id, crypto_pwhash_str format
};

//! 1..31 characters of [A-Za-z0-9._-] (the operator id on the wire holds 31).
Status valid_user_name(const std::string& user);
//! The accounts; errors name the file and line.
Result<std::vector<Account>> read_accounts(const std::string& path);
//! [bytes] the longest password taken.
inline constexpr std::size_t kMaxPasswordBytes = 1024;
//! The password a line of input gives: without a final carriage return (a line ended by CR LF), 8 to
//! kMaxPasswordBytes bytes; bad input otherwise.
Result<std::string> password_of_line(std::string line);
//! argon2id with libsodium's interactive limits (64 MiB, 2 passes); bad input beyond kMaxPasswordBytes.
Result<std::string> hash_password(const std::string& password);
//! Adds or replaces the account's line, keeping every other line; the file is written anew beside the
//! old one and renamed over it (mode 0600).
Status set_account(const std::string& path, const Account& account);

struct Session {
  std::string user;
  Role role = Role::kViewer;
  std::string csrf;       //!< the token state-changing requests must carry (bound to this session)
  bool by_proxy = false;  //!< authenticated by the trusted proxy (no session of the ground's to sign out)
};

class Operators {
 public:
  //! Reads the accounts; reads the session key from `key_path`, creating it (mode 0600) when absent and
  //! refusing it when group or others may read it; opens the session journal `sessions_path`.
  static Result<Operators> open(const std::string& users_path, const std::string& key_path,
                                const std::string& sessions_path, std::int64_t now_s);
  Operators(Operators&& other) noexcept;

  //! The account when the password matches (the same work is done for an unknown user).
  std::optional<Account> login(const std::string& user, const std::string& password);
  //! A new session id for the user, valid `lifetime_s` from `now_s` (UTC seconds), recorded in the journal.
  Result<std::string> issue(const std::string& user, std::int64_t now_s, std::int64_t lifetime_s);
  //! The session of an id: in the journal, not expired, not signed out, its account still there.
  std::optional<Session> session(const std::string& token, std::int64_t now_s);
  //! The session of a user the trusted proxy authenticated: their account's role, a CSRF token bound to
  //! the user (keyed: stable across restarts, unforgeable); none without an account.
  std::optional<Session> by_proxy(const std::string& user);
  //! Signs the session out for good (recorded in the journal).
  Status revoke(const std::string& token);
  //! The CSRF token of a session token.
  std::string csrf(const std::string& token) const;

 private:
  Operators() = default;
  void reload();
  //! The session of the user's account (none without one); the lock held.
  std::optional<Session> session_of_account(const std::string& user, const std::string& csrf_of_what);
  std::string users_path_;
  std::string key_;
  std::mutex mutex_;
  std::vector<Account> accounts_;
  FileStamp accounts_stamp_;
  std::optional<SessionStore> sessions_;
  std::string dummy_hash_;
};

//! The CSRF token of a session token (keyed hash; the same for every request of the session).
std::string csrf_of(const std::string& key, const std::string& token);
//! The keyed BLAKE2b (32 bytes) of `text`, as hexadecimal.
std::string keyed_hash_hex(const std::string& key, const std::string& text);
//! Constant-time comparison.
bool same_secret(const std::string& a, const std::string& b);
//! `n` random bytes as hexadecimal.
std::string random_hex(std::size_t n);
//! Bytes as lowercase hexadecimal, two digits each.
std::string hex_of(std::string_view bytes);

}  // namespace tetra::ground
