#include "tetra/ground/operators.hpp"

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <sstream>

#include "tetra/core/csv.hpp"
#include "tetra/ground/private_file.hpp"

namespace tetra::ground {

namespace {

//! What group or others could do with the accounts file or the session key.
constexpr const char* kAnyOperator = "whoever reads it can sign in as any operator";

bool sodium_ready() {
  static const bool ready = sodium_init() >= 0;
  return ready;
}

}  // namespace

std::string hex_of(std::string_view bytes) {
  std::string out(bytes.size() * 2 + 1, '\0');
  sodium_bin2hex(out.data(), out.size(), reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
  out.pop_back();
  return out;
}

std::string keyed_hash_hex(const std::string& key, const std::string& text) {
  sodium_ready();
  unsigned char mac[32];
  crypto_generichash(mac, sizeof mac, reinterpret_cast<const unsigned char*>(text.data()), text.size(),
                     reinterpret_cast<const unsigned char*>(key.data()), key.size());
  return hex_of(std::string_view(reinterpret_cast<const char*>(mac), sizeof mac));
}

const char* to_string(Role role) {
  return role == Role::kCommander ? "commander" : "viewer";
}

std::optional<Role> role_named(const std::string& name) {
  if (name == "viewer") return Role::kViewer;
  if (name == "commander") return Role::kCommander;
  return std::nullopt;
}

Status valid_user_name(const std::string& user) {
  if (user.empty() || user.size() > 31 ||
      user.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789._-") !=
          std::string::npos)
    return bad_input("user '" + user + "': 1 to 31 characters of A-Z a-z 0-9 . _ -");
  return ok_status();
}

std::string random_hex(std::size_t n) {
  sodium_ready();
  std::string bytes(n, '\0');
  randombytes_buf(bytes.data(), n);
  return hex_of(bytes);
}

bool same_secret(const std::string& a, const std::string& b) {
  return a.size() == b.size() && !a.empty() && sodium_memcmp(a.data(), b.data(), a.size()) == 0;
}

std::string csrf_of(const std::string& key, const std::string& token) {
  return keyed_hash_hex(key, "csrf:" + token);
}

Result<std::vector<Account>> read_accounts(const std::string& path) {
  auto text = read_text_file(path);
  if (!text) return text.error();
  std::vector<Account> accounts;
  std::istringstream in(*text);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    const std::string where = path + ":" + std::to_string(number);
    const auto c1 = line.find(':');
    const auto c2 = c1 == std::string::npos ? c1 : line.find(':', c1 + 1);
    if (c2 == std::string::npos) return bad_input(where + ": expected user:role:hash");
    Account a;
    a.user = line.substr(0, c1);
    if (auto s = valid_user_name(a.user); !s) return bad_input(where + ": " + s.error().message);
    const auto role = role_named(line.substr(c1 + 1, c2 - c1 - 1));
    if (!role) return bad_input(where + ": role must be viewer or commander");
    a.role = *role;
    a.hash = line.substr(c2 + 1);
    if (a.hash.rfind("$argon2id$", 0) != 0) return bad_input(where + ": the hash is not argon2id");
    // A damaged hash (cut short, a carriage return, parameters out of range) would never sign in.
    if (!sodium_ready() ||
        crypto_pwhash_argon2id_str_needs_rehash(a.hash.c_str(), crypto_pwhash_OPSLIMIT_INTERACTIVE,
                                                crypto_pwhash_MEMLIMIT_INTERACTIVE) < 0)
      return bad_input(where +
                       ": the argon2id hash is damaged (set the password again with tetra ground passwd)");
    for (const auto& other : accounts) {
      if (other.user == a.user) return bad_input(where + ": user '" + a.user + "' given twice");
    }
    accounts.push_back(std::move(a));
  }
  return accounts;
}

Result<std::string> password_of_line(std::string line) {
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line.size() < 8) return bad_input("password: at least 8 characters");
  if (line.size() > kMaxPasswordBytes)
    return bad_input("password: at most " + std::to_string(kMaxPasswordBytes) + " characters");
  return line;
}

Result<std::string> hash_password(const std::string& password) {
  if (!sodium_ready()) return failure("libsodium cannot start");
  if (password.size() > kMaxPasswordBytes)
    return bad_input("password: at most " + std::to_string(kMaxPasswordBytes) + " characters");
  char out[crypto_pwhash_STRBYTES];
  if (crypto_pwhash_str(out, password.data(), password.size(), crypto_pwhash_OPSLIMIT_INTERACTIVE,
                        crypto_pwhash_MEMLIMIT_INTERACTIVE) != 0)
    return failure("password hash: out of memory");
  return std::string(out);
}

Status set_account(const std::string& path, const Account& account) {
  if (auto s = valid_user_name(account.user); !s) return s;
  std::string text;
  if (::access(path.c_str(), F_OK) == 0) {
    if (auto existing = read_accounts(path); !existing) return existing.error();
    auto old = read_text_file(path);
    if (!old) return old.error();
    std::istringstream in(*old);
    for (std::string line; std::getline(in, line);) {
      if (line.rfind(account.user + ":", 0) != 0) text += line + "\n";
    }
  } else {
    text = "# tetra ground operators (tetra ground passwd): user:role:argon2id hash\n";
  }
  text += account.user + ":" + to_string(account.role) + ":" + account.hash + "\n";
  return write_private(path, text);
}

Result<Operators> Operators::open(const std::string& users_path, const std::string& key_path,
                                  const std::string& sessions_path, std::int64_t now_s) {
  if (!sodium_ready()) return failure("libsodium cannot start");
  Operators ops;
  ops.users_path_ = users_path;
  if (auto s = check_private(users_path, "the accounts file", kAnyOperator); !s) return s.error();
  auto accounts = read_accounts(users_path);
  if (!accounts) return accounts.error();
  if (accounts->empty())
    return bad_input(users_path + ": no accounts (add one with tetra ground passwd USER --users " +
                     users_path + ")");
  ops.accounts_ = std::move(accounts).value();
  ops.accounts_stamp_ = file_stamp(users_path);
  if (auto s = check_private(key_path, "the session key", kAnyOperator); !s) return s.error();
  auto key = read_text_file(key_path);
  if (!key) {
    if (::access(key_path.c_str(), F_OK) == 0) return key.error();
    if (auto s = write_private(key_path, random_hex(32) + "\n"); !s) return s.error();
    key = read_text_file(key_path);
    if (!key) return key.error();
  }
  ops.key_ = key->substr(0, key->find('\n'));
  if (ops.key_.size() < 32) return bad_input(key_path + ": a session key of at least 32 characters");
  auto sessions = SessionStore::open(sessions_path, ops.key_, now_s);
  if (!sessions) return sessions.error();
  ops.sessions_.emplace(std::move(sessions).value());
  return ops;
}

Operators::Operators(Operators&& other) noexcept
    : users_path_(std::move(other.users_path_)),
      key_(std::move(other.key_)),
      accounts_(std::move(other.accounts_)),
      accounts_stamp_(other.accounts_stamp_),
      sessions_(std::move(other.sessions_)),
      dummy_hash_(std::move(other.dummy_hash_)) {}

void Operators::reload() {
  const FileStamp stamp = file_stamp(users_path_);
  if (stamp == accounts_stamp_) return;
  auto accounts = read_accounts(users_path_);
  accounts_stamp_ = stamp;
  // A file being edited, broken or opened to others: no accounts until it reads again (refuse rather
  // than guess).
  accounts_ = accounts && check_private(users_path_, "the accounts file", kAnyOperator)
                  ? std::move(accounts).value()
                  : std::vector<Account>{};
}

std::optional<Account> Operators::login(const std::string& user, const std::string& password) {
  std::optional<Account> account;
  {
    const std::lock_guard lock(mutex_);
    reload();
    for (const auto& a : accounts_) {
      if (a.user == user) account = a;
    }
    if (!account && dummy_hash_.empty()) {
      auto h = hash_password(random_hex(16));
      dummy_hash_ = h ? *h : std::string();
    }
  }
  const std::string& hash = account ? account->hash : dummy_hash_;
  const bool match =
      !hash.empty() && crypto_pwhash_str_verify(hash.c_str(), password.data(), password.size()) == 0;
  return account && match ? account : std::nullopt;
}

Result<std::string> Operators::issue(const std::string& user, std::int64_t now_s, std::int64_t lifetime_s) {
  const std::lock_guard lock(mutex_);
  return sessions_->issue(user, now_s, lifetime_s);
}

std::optional<Session> Operators::session(const std::string& token, std::int64_t now_s) {
  const std::lock_guard lock(mutex_);
  const auto user = sessions_->user_of(token, now_s);
  if (!user) return std::nullopt;
  return session_of_account(*user, token);
}

std::optional<Session> Operators::by_proxy(const std::string& user) {
  const std::lock_guard lock(mutex_);
  auto session = session_of_account(user, "proxy:" + user);
  if (session) session->by_proxy = true;
  return session;
}

std::optional<Session> Operators::session_of_account(const std::string& user,
                                                     const std::string& csrf_of_what) {
  reload();
  for (const auto& a : accounts_) {
    if (a.user == user) return Session{a.user, a.role, csrf_of(key_, csrf_of_what)};
  }
  return std::nullopt;
}

std::string Operators::csrf(const std::string& token) const {
  return csrf_of(key_, token);
}

Status Operators::revoke(const std::string& token) {
  const std::lock_guard lock(mutex_);
  return sessions_->revoke(token);
}

}  // namespace tetra::ground
