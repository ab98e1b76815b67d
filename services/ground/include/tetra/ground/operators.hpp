#pragma once
// Operator accounts of the ground station (docs/ground.md, "Accounts"): a file of `user:role:hash` lines,
// the hash argon2id (libsodium's crypto_pwhash_str, memory-hard), managed by `tetra ground passwd`; and
// sessions as signed tokens (keyed BLAKE2b over user, expiry and a nonce, with a key kept in a file of
// its own), so a session survives a restart of the ground station. A session's role is read from the
// accounts file at each request: a changed role or a removed account takes effect at once.

#include <cstdint>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "tetra/core/result.hpp"

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
//! argon2id with libsodium's interactive limits (64 MiB, 2 passes).
Result<std::string> hash_password(const std::string& password);
//! Adds or replaces the account's line, keeping every other line; the file is written anew beside the
//! old one and renamed over it (mode 0600).
Status set_account(const std::string& path, const Account& account);

struct Session {
  std::string user;
  Role role = Role::kViewer;
  std::string csrf;  //!< the token state-changing requests must carry (bound to this session)
};

class Operators {
 public:
  //! Reads the accounts; reads the session key from `key_path`, creating it (mode 0600) when absent.
  static Result<Operators> open(const std::string& users_path, const std::string& key_path);
  Operators(Operators&& other) noexcept;

  //! The account when the password matches (the same work is done for an unknown user).
  std::optional<Account> login(const std::string& user, const std::string& password);
  //! A session token for the user, valid `lifetime_s` from `now_s` (UTC seconds).
  std::string issue(const std::string& user, std::int64_t now_s, std::int64_t lifetime_s);
  //! The session of a token: signed by this key, not expired, not revoked, its account still there.
  std::optional<Session> session(const std::string& token, std::int64_t now_s);
  void revoke(const std::string& token);
  //! The CSRF token of a session token.
  std::string csrf(const std::string& token) const;

 private:
  Operators() = default;
  void reload();
  std::string users_path_;
  std::string key_;
  std::mutex mutex_;
  std::vector<Account> accounts_;
  std::int64_t accounts_mtime_ns_ = -1;
  std::set<std::string> revoked_;
  std::string dummy_hash_;
};

//! The CSRF token of a session token (keyed hash; the same for every request of the session).
std::string csrf_of(const std::string& key, const std::string& token);
//! Constant-time comparison.
bool same_secret(const std::string& a, const std::string& b);
//! `n` random bytes as hexadecimal.
std::string random_hex(std::size_t n);

}  // namespace tetra::ground
