#pragma once
// Shared by the libFuzzer targets: a check that reports what broke and aborts, so libFuzzer records
// the input as a crash. Properties checked by the targets are promises of the libraries: a parse
// either succeeds with a self-consistent value or fails with a one-line message — never a crash.

#include <cstdio>
#include <cstdlib>
#include <string>

#include "tetra/core/result.hpp"

#define TETRA_FUZZ_CHECK(cond)                                                                \
  do {                                                                                        \
    if (!(cond)) {                                                                            \
      std::fprintf(stderr, "fuzz property failed at %s:%d: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                           \
    }                                                                                         \
  } while (false)

namespace tetra::fuzz {

//! An error a CLI prints as "one line on stderr": non-empty and without a newline.
inline void check_error_message(const Error& error) {
  if (error.message.empty() || error.message.find('\n') != std::string::npos) {
    std::fprintf(stderr, "error message is not one line: [%s]\n", error.message.c_str());
    std::abort();
  }
}

}  // namespace tetra::fuzz
