// libFuzzer target: the DDS Security profile reader (services/fusion/security_profile.hpp) on
// arbitrary bytes: a profile with all six documents, or a one-line error.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_check.hpp"
#include "tetra/service/security_profile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const auto profile = tetra::service::parse_security_profile(text, "fuzz.yaml", "/pki");
  if (!profile) {
    tetra::fuzz::check_error_message(profile.error());
    return 0;
  }
  for (const std::string* f : {&profile->identity_ca, &profile->identity_certificate, &profile->private_key,
                               &profile->permissions_ca, &profile->governance, &profile->permissions}) {
    TETRA_FUZZ_CHECK(!f->empty());
  }
  (void)tetra::service::describe(*profile);
  return 0;
}
