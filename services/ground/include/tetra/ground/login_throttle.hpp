#pragma once
// Password guessing (docs/ground.md, "Guessing"): every sign-in is admitted or refused before its
// password is checked, by the failures of its client address and of its account within a sliding
// window. An address gets a few failures free, then waits a doubling delay after each failure; an
// account that has taken its cap of failures within the window is locked, except for the addresses it
// has signed in from: a guesser on one address never locks the operator out of another. A refused
// attempt costs no password check and is not counted. Every map is bounded.

#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

namespace tetra::ground {

struct ThrottleLimits {
  double window_s = 3600.0;         //!< [s] failures count for this long
  int address_free = 5;             //!< failures of an address within the window before it backs off
  double backoff_first_s = 1.0;     //!< [s] the first wait; doubling with each further failure
  double backoff_max_s = 60.0;      //!< [s] the longest wait
  int account_max = 100;            //!< failures of an account within the window: then locked (ASVS 2.2.1)
  std::size_t max_tracked = 16384;  //!< addresses, and accounts, remembered at most
  std::size_t proven_per_account = 16;  //!< addresses an account signed in from, remembered at most
};

struct ThrottleVerdict {
  bool allowed = true;
  double retry_after_s = 0;  //!< [s] when refused: how long until an attempt may be admitted
  std::string reason;        //!< when refused
  //! When refused: refusals of this address since its last admitted attempt, this one excluded (the
  //! audit records the 1st, 2nd, 4th, 8th...: a client hammering a back-off does not flood the file).
  std::uint64_t refused_before = 0;
};

class LoginThrottle {
 public:
  explicit LoginThrottle(ThrottleLimits limits = {});
  //! Before the password is checked. An admitted attempt counts as a failure until record() says
  //! otherwise, so attempts in flight at once are counted too.
  ThrottleVerdict admit(const std::string& user, const std::string& address, std::int64_t now_ns);
  //! After the check of an admitted attempt (`now_ns` the admit's).
  void record(const std::string& user, const std::string& address, bool success, std::int64_t now_ns);
  //! The key of an address: itself for IPv4, its /64 prefix for IPv6 (one host holds a whole /64).
  static std::string address_key(const std::string& address);

 private:
  struct Times {
    std::deque<std::int64_t> at;  //!< failures within the window, oldest first
    std::uint64_t refused = 0;    //!< refusals since the last admitted attempt
  };
  void prune(Times& t, std::int64_t now_ns) const;
  Times& entry(std::unordered_map<std::string, Times>& map, const std::string& key, std::int64_t now_ns);
  ThrottleLimits limits_;
  std::mutex mutex_;
  std::unordered_map<std::string, Times> by_address_;
  std::unordered_map<std::string, Times> by_account_;
  std::unordered_map<std::string, std::vector<std::string>> proven_;  //!< account → addresses, newest last
};

}  // namespace tetra::ground
