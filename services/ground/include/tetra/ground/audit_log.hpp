#pragma once
// The ground station's audit trail (docs/ground.md, "Audit"): one JSON object per line per decision —
// a sign-in, a sign-out, a command and its answer, every refused request (a refused cookie too) — in a
// file of its own (mode 0600, appended), each field escaped by the JSON encoder, so nothing a client
// sends can end a line or forge one. The same decision is a one-line `ground audit:` log line with every
// control character escaped.

#include <mutex>
#include <string>

#include "tetra/core/result.hpp"

namespace tetra::ground {

struct AuditRecord {
  std::string decision;               //!< "sign-in", "sign-out", "command", "session", "request"
  std::string outcome;                //!< "accepted", "refused", "unanswered" (a command without an answer)
  std::string decided_by = "ground";  //!< "ground" or "service" (a command's acknowledgement)
  int status = 0;                     //!< the HTTP status answered
  std::string operator_id;            //!< the signed-in user, the user a sign-in named, "" without one
  std::string role;                   //!< of the operator, when known
  std::string address;                //!< the client's
  std::string method;
  std::string path;
  std::string unit;     //!< a command's
  std::string command;  //!< a command's, e.g. "exclude gyro 3 force"
  std::string reason;   //!< why refused, or the service's detail
};

class AuditLog {
 public:
  //! Opens (creates, mode 0600) `path` for appending; "" keeps the log lines only. Refused when group
  //! or others may read or write it.
  static Result<AuditLog> open(const std::string& path);
  AuditLog() = default;
  AuditLog(AuditLog&& other) noexcept;
  AuditLog& operator=(AuditLog&& other) noexcept;
  ~AuditLog();
  //! Appends the record (one write) and logs its line; a failed write is logged, never thrown.
  void write(const AuditRecord& record);
  //! The record as one JSON line (with its UTC time, `time_ms` since 1970), ending in '\n'.
  static std::string json_line(const AuditRecord& record, std::int64_t utc_ms);
  //! The record as a log line's text (control characters escaped).
  static std::string summary(const AuditRecord& record);

 private:
  int fd_ = -1;
  std::string path_;
  std::mutex mutex_;
};

}  // namespace tetra::ground
