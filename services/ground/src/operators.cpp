#include "tetra/ground/operators.hpp"

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <sstream>

#include "tetra/core/csv.hpp"

namespace tetra::ground {

namespace {

bool sodium_ready() {
  static const bool ready = sodium_init() >= 0;
  return ready;
}

std::string to_hex(const unsigned char* data, std::size_t n) {
  std::string out(n * 2 + 1, '\0');
  sodium_bin2hex(out.data(), out.size(), data, n);
  out.pop_back();
  return out;
}

std::int64_t mtime_ns(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return -1;
  return static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1000000000LL + st.st_mtim.tv_nsec;
}

//! Writes `text` to `path` with mode 0600: a new file beside it, renamed over it.
Status write_private(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".new" + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) return failure(path + ": cannot write (" + tmp + ")");
  const bool written =
      ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()) && ::fsync(fd) == 0;
  ::close(fd);
  if (!written || ::rename(tmp.c_str(), path.c_str()) != 0) {
    ::unlink(tmp.c_str());
    return failure(path + ": cannot write");
  }
  return ok_status();
}

//! "user.expiry.nonce" and its keyed hash.
std::string signature(const std::string& key, const std::string& text) {
  unsigned char mac[32];
  crypto_generichash(mac, sizeof mac, reinterpret_cast<const unsigned char*>(text.data()), text.size(),
                     reinterpret_cast<const unsigned char*>(key.data()), key.size());
  return to_hex(mac, sizeof mac);
}

}  // namespace

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
  return to_hex(reinterpret_cast<const unsigned char*>(bytes.data()), n);
}

bool same_secret(const std::string& a, const std::string& b) {
  return a.size() == b.size() && !a.empty() && sodium_memcmp(a.data(), b.data(), a.size()) == 0;
}

std::string csrf_of(const std::string& key, const std::string& token) {
  return signature(key, "csrf:" + token);
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
    for (const auto& other : accounts) {
      if (other.user == a.user) return bad_input(where + ": user '" + a.user + "' given twice");
    }
    accounts.push_back(std::move(a));
  }
  return accounts;
}

Result<std::string> hash_password(const std::string& password) {
  if (!sodium_ready()) return failure("libsodium cannot start");
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

Result<Operators> Operators::open(const std::string& users_path, const std::string& key_path) {
  if (!sodium_ready()) return failure("libsodium cannot start");
  Operators ops;
  ops.users_path_ = users_path;
  auto accounts = read_accounts(users_path);
  if (!accounts) return accounts.error();
  ops.accounts_ = std::move(accounts).value();
  ops.accounts_mtime_ns_ = mtime_ns(users_path);
  auto key = read_text_file(key_path);
  if (!key) {
    if (::access(key_path.c_str(), F_OK) == 0) return key.error();
    if (auto s = write_private(key_path, random_hex(32) + "\n"); !s) return s.error();
    key = read_text_file(key_path);
    if (!key) return key.error();
  }
  ops.key_ = key->substr(0, key->find('\n'));
  if (ops.key_.size() < 32) return bad_input(key_path + ": a session key of at least 32 characters");
  return ops;
}

Operators::Operators(Operators&& other) noexcept
    : users_path_(std::move(other.users_path_)),
      key_(std::move(other.key_)),
      accounts_(std::move(other.accounts_)),
      accounts_mtime_ns_(other.accounts_mtime_ns_),
      revoked_(std::move(other.revoked_)),
      dummy_hash_(std::move(other.dummy_hash_)) {}

void Operators::reload() {
  const std::int64_t m = mtime_ns(users_path_);
  if (m == accounts_mtime_ns_) return;
  auto accounts = read_accounts(users_path_);
  accounts_mtime_ns_ = m;
  // A file being edited or broken: no accounts until it reads again (refuse rather than guess).
  accounts_ = accounts ? std::move(accounts).value() : std::vector<Account>{};
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

std::string Operators::issue(const std::string& user, std::int64_t now_s, std::int64_t lifetime_s) {
  const std::string text = user + "." + std::to_string(now_s + lifetime_s) + "." + random_hex(16);
  return text + "." + signature(key_, text);
}

std::optional<Session> Operators::session(const std::string& token, std::int64_t now_s) {
  const auto dot = token.rfind('.');
  if (dot == std::string::npos || token.size() > 256) return std::nullopt;
  const std::string text = token.substr(0, dot);
  if (!same_secret(token.substr(dot + 1), signature(key_, text))) return std::nullopt;
  const auto d1 = text.find('.');
  const auto d2 = text.find('.', d1 + 1);
  if (d1 == std::string::npos || d2 == std::string::npos) return std::nullopt;
  const std::string user = text.substr(0, d1);
  const std::string expiry = text.substr(d1 + 1, d2 - d1 - 1);
  if (expiry.empty() || expiry.size() > 18 || expiry.find_first_not_of("0123456789") != std::string::npos ||
      std::stoll(expiry) < now_s)
    return std::nullopt;
  const std::lock_guard lock(mutex_);
  if (revoked_.count(token) != 0) return std::nullopt;
  reload();
  for (const auto& a : accounts_) {
    if (a.user == user) return Session{user, a.role, csrf_of(key_, token)};
  }
  return std::nullopt;
}

std::string Operators::csrf(const std::string& token) const {
  return csrf_of(key_, token);
}

void Operators::revoke(const std::string& token) {
  const std::lock_guard lock(mutex_);
  if (revoked_.size() > 100000) revoked_.clear();  // bounded; tokens expire anyway
  revoked_.insert(token);
}

}  // namespace tetra::ground
