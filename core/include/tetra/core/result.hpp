#pragma once
// Error values for the tetra libraries. A library never exits or aborts on bad input:
// it returns an Error whose message names what was wrong (file, line, field where known).
// A library message never names a command-line option: an error about an argument of a library
// call carries the argument in Error::subject, and the command maps it to its own option.
// Command-line adapters turn an Error into exit status 2 (bad input) or 1 (other failure).

#include <string>
#include <utility>
#include <variant>

namespace tetra {

enum class ErrorKind {
  kBadInput,  //!< malformed file, bad value, bad usage: the user can fix it (exit 2)
  kFailure,   //!< anything else: I/O, middleware, internal (exit 1)
};

//! The argument of a library call (or the output it makes) an Error is about, by the library's own
//! name for it (the parameter or configuration key, e.g. "taus", "gyros"), and the one value of it the
//! message is about when there is one ("5" for gyro 5 of a list). The message reads after it: "taus:
//! averaging time 0 s is not positive", "gyros 5: the log has gyros 1..4".
struct ErrorSubject {
  ErrorSubject() = default;
  ErrorSubject(std::string name_, std::string value_ = {})  // NOLINT(google-explicit-constructor)
      : name(std::move(name_)), value(std::move(value_)) {}
  std::string name;   //!< empty: the message names what was wrong itself (file, line, field)
  std::string value;  //!< may be empty
  bool operator==(const ErrorSubject&) const = default;
};

struct Error {
  std::string message;                    //!< one line, no trailing newline
  ErrorKind kind = ErrorKind::kBadInput;  //!< how a CLI should report it
  ErrorSubject subject = {};              //!< the argument it is about, if any (see ErrorSubject)
};

//! Keeps a message on one line: control characters (which messages may quote from bad input, e.g. a
//! newline inside a YAML scalar) are written as escapes \n, \r, \t, \xHH.
inline std::string one_line(const std::string& message) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(message.size());
  for (const char c : message) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u != 0x7f) {
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else {
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 0xf];
    }
  }
  return out;
}

inline Error bad_input(const std::string& message) {
  return Error{one_line(message), ErrorKind::kBadInput};
}
inline Error failure(const std::string& message) {
  return Error{one_line(message), ErrorKind::kFailure};
}
//! Bad input about an argument of the call: `message` reads after the subject.
inline Error bad_input(ErrorSubject subject, const std::string& message) {
  return Error{one_line(message), ErrorKind::kBadInput, std::move(subject)};
}
//! Another failure about an argument of the call: `message` reads after the subject.
inline Error failure(ErrorSubject subject, const std::string& message) {
  return Error{one_line(message), ErrorKind::kFailure, std::move(subject)};
}

//! The whole message in the library's words: "subject value: message", or the message alone.
inline std::string describe(const Error& error) {
  const ErrorSubject& s = error.subject;
  if (s.name.empty()) return error.message;
  return s.name + (s.value.empty() ? "" : " " + one_line(s.value)) + ": " + error.message;
}

//! Either a value or an Error. Minimal stand-in for C++23 std::expected.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : state_(std::move(value)) {}      // NOLINT(google-explicit-constructor)
  Result(Error error) : state_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

  bool ok() const { return std::holds_alternative<T>(state_); }
  explicit operator bool() const { return ok(); }

  T& value() & { return std::get<T>(state_); }
  const T& value() const& { return std::get<T>(state_); }
  T&& value() && { return std::get<T>(std::move(state_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

  const Error& error() const { return std::get<Error>(state_); }

 private:
  std::variant<T, Error> state_;
};

//! Result of an operation that yields nothing but may fail.
struct Ok {};
using Status = Result<Ok>;
inline Status ok_status() {
  return Ok{};
}

}  // namespace tetra
