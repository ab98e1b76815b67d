#include "tetra/ground/audit_log.hpp"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <nlohmann/json.hpp>

#include "tetra/ground/private_file.hpp"
#include "tetra/ground/unit_id.hpp"

namespace tetra::ground {

namespace {

//! What group or others could do with the audit file: it signs no one in, but tells and keeps the record.
constexpr const char* kOpenAuditFile =
    "whoever reads it learns who signed in from where and what they commanded, whoever writes it can forge "
    "or "
    "erase the record";

}  // namespace

Result<AuditLog> AuditLog::open(const std::string& path) {
  AuditLog log;
  if (path.empty()) return log;
  if (auto s = check_private(path, "the audit file", kOpenAuditFile); !s) return s.error();
  log.fd_ = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0600);
  if (log.fd_ < 0) return failure(path + ": cannot open the audit file: " + std::strerror(errno));
  log.path_ = path;
  return log;
}

AuditLog::AuditLog(AuditLog&& other) noexcept : fd_(other.fd_), path_(std::move(other.path_)) {
  other.fd_ = -1;
}

AuditLog& AuditLog::operator=(AuditLog&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.fd_;
    path_ = std::move(other.path_);
    other.fd_ = -1;
  }
  return *this;
}

AuditLog::~AuditLog() {
  if (fd_ >= 0) ::close(fd_);
}

std::string AuditLog::json_line(const AuditRecord& r, std::int64_t utc_ms) {
  const nlohmann::json j = {{"time_ms", utc_ms},    {"decision", r.decision},
                            {"outcome", r.outcome}, {"decided_by", r.decided_by},
                            {"status", r.status},   {"operator", r.operator_id},
                            {"role", r.role},       {"address", r.address},
                            {"method", r.method},   {"path", r.path},
                            {"unit", r.unit},       {"unit_id", unit_id(r.unit)},
                            {"command", r.command}, {"reason", r.reason}};
  // Every string escaped (control characters as \uXXXX, bytes that are not UTF-8 as U+FFFD).
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

std::string AuditLog::summary(const AuditRecord& r) {
  const std::string who = r.operator_id.empty() ? "no session" : "user " + one_line(r.operator_id);
  std::string line;
  if ((r.decision == "command" && (r.decided_by == "service" || r.outcome == "pending")) ||
      r.decision == "approval") {
    line = one_line(r.operator_id) + " from " + one_line(r.address) + ": " + one_line(r.command) + " to " +
           one_line(r.unit) + ": " + r.outcome + " (" + one_line(r.reason) + ")";
  } else if (r.outcome == "refused" || r.outcome == "unanswered") {
    line = r.outcome + " " + one_line(r.method) + " " + one_line(r.path) + " from " + one_line(r.address) +
           " (" + who + "): " + one_line(r.reason);
  } else if (r.decision == "sign-in") {
    line = one_line(r.operator_id) + " (" + one_line(r.role) + ") signed in from " + one_line(r.address);
  } else {
    line = one_line(r.operator_id) + " " + r.decision + " from " + one_line(r.address);
  }
  return line;
}

void AuditLog::write(const AuditRecord& record) {
  if (record.outcome == "accepted") {
    spdlog::info("ground audit: {}", summary(record));
  } else {
    spdlog::warn("ground audit: {}", summary(record));
  }
  if (fd_ < 0) return;
  const auto utc_ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                          std::chrono::system_clock::now().time_since_epoch())
                          .count();
  const std::string line = json_line(record, utc_ms);
  const std::lock_guard lock(mutex_);
  // O_APPEND: one write is one line, whole, after every other.
  const ssize_t n = ::write(fd_, line.data(), line.size());
  if (n != static_cast<ssize_t>(line.size()))
    spdlog::error("ground: {}: the audit record was not written whole: {}", path_, std::strerror(errno));
}

}  // namespace tetra::ground
