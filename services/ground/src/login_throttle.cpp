#include "tetra/ground/login_throttle.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace tetra::ground {

namespace {

std::int64_t ns_of(double s) {
  return static_cast<std::int64_t>(s * 1e9);
}

void forget_one(std::deque<std::int64_t>& times, std::int64_t at) {
  const auto it = std::find(times.rbegin(), times.rend(), at);
  if (it != times.rend()) times.erase(std::next(it).base());
}

}  // namespace

LoginThrottle::LoginThrottle(ThrottleLimits limits) : limits_(limits) {}

std::string LoginThrottle::address_key(const std::string& address) {
  in6_addr a{};
  // IPv4 (also as ::ffff:a.b.c.d on a dual-stack socket) is keyed by the whole address.
  if (::inet_pton(AF_INET6, address.c_str(), &a) != 1 || IN6_IS_ADDR_V4MAPPED(&a)) return address;
  std::memset(reinterpret_cast<unsigned char*>(&a) + 8, 0, 8);
  char text[INET6_ADDRSTRLEN] = "";
  ::inet_ntop(AF_INET6, &a, text, sizeof text);
  return std::string(text) + "/64";
}

void LoginThrottle::prune(Times& t, std::int64_t now_ns) const {
  while (!t.at.empty() && now_ns - t.at.front() > ns_of(limits_.window_s)) t.at.pop_front();
}

LoginThrottle::Times& LoginThrottle::entry(std::unordered_map<std::string, Times>& map,
                                           const std::string& key, std::int64_t now_ns) {
  if (const auto it = map.find(key); it != map.end()) {
    prune(it->second, now_ns);
    return it->second;
  }
  if (map.size() >= limits_.max_tracked) {
    // Full: forget what has aged out, else the entry with the fewest failures (a flood of new names or
    // addresses never pushes out one with many).
    for (auto it = map.begin(); it != map.end();) {
      prune(it->second, now_ns);
      it = it->second.at.empty() ? map.erase(it) : std::next(it);
    }
    if (map.size() >= limits_.max_tracked) {
      map.erase(std::min_element(map.begin(), map.end(), [](const auto& a, const auto& b) {
        return a.second.at.size() < b.second.at.size();
      }));
    }
  }
  return map[key];
}

ThrottleVerdict LoginThrottle::admit(const std::string& user, const std::string& address,
                                     std::int64_t now_ns) {
  const std::lock_guard lock(mutex_);
  const std::string where = address_key(address);
  Times& from = entry(by_address_, where, now_ns);
  ThrottleVerdict v;
  const int failures = static_cast<int>(from.at.size());
  if (failures >= limits_.address_free) {
    const double wait_s = std::min(limits_.backoff_max_s,
                                   limits_.backoff_first_s * std::pow(2.0, failures - limits_.address_free));
    const std::int64_t next_ns = from.at.back() + ns_of(wait_s);
    if (now_ns < next_ns) {
      v.allowed = false;
      v.refused_before = from.refused++;
      v.retry_after_s = static_cast<double>(next_ns - now_ns) / 1e9;
      v.reason = std::to_string(failures) + " failed sign-ins from this address within the hour: wait";
      return v;
    }
  }
  Times& account = entry(by_account_, user, now_ns);
  if (static_cast<int>(account.at.size()) >= limits_.account_max) {
    const auto proven = proven_.find(user);
    if (proven == proven_.end() ||
        std::find(proven->second.begin(), proven->second.end(), where) == proven->second.end()) {
      v.allowed = false;
      v.refused_before = from.refused++;
      v.retry_after_s = static_cast<double>(account.at.front() + ns_of(limits_.window_s) - now_ns) / 1e9;
      v.reason = "account locked: " + std::to_string(account.at.size()) +
                 " failed sign-ins within the hour (it still opens from an address it signed in from)";
      return v;
    }
  }
  from.at.push_back(now_ns);
  from.refused = 0;
  account.at.push_back(now_ns);
  return v;
}

void LoginThrottle::record(const std::string& user, const std::string& address, bool success,
                           std::int64_t now_ns) {
  if (!success) return;  // admit() counted it already
  const std::lock_guard lock(mutex_);
  const std::string where = address_key(address);
  if (const auto it = by_address_.find(where); it != by_address_.end()) forget_one(it->second.at, now_ns);
  if (const auto it = by_account_.find(user); it != by_account_.end()) forget_one(it->second.at, now_ns);
  auto& proven = proven_[user];
  proven.erase(std::remove(proven.begin(), proven.end(), where), proven.end());
  proven.push_back(where);
  if (proven.size() > limits_.proven_per_account) proven.erase(proven.begin());
}

}  // namespace tetra::ground
