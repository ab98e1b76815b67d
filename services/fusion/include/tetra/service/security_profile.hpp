#pragma once
// DDS Security profile of one participant (docs/reliability.md): the six documents the OMG DDS
// Security built-in plugins need, as a small YAML file written by scripts/security/make_pki.sh:
//
//   identity_ca: identity_ca.pem            # CA that signed every participant's certificate
//   identity_certificate: fusion.pem        # this participant's certificate
//   private_key: fusion.key                 # its private key
//   permissions_ca: permissions_ca.pem      # CA that signed governance and permissions
//   governance: governance.p7s              # signed domain rules
//   permissions: permissions.p7s            # signed grants (the certificate's subject must have one)
//
// Relative paths are relative to the profile file. Every key is required; unknown keys are errors.
// The profile itself is plain data (tetra/service_types/security_profile.hpp): services/dds turns it
// into participant QoS properties. No DDS header here.

#include <string>

#include "tetra/core/result.hpp"
#include "tetra/service_types/security_profile.hpp"

namespace tetra::service {

//! Parses a profile; relative paths are resolved against `base_dir`. Does not touch the files.
Result<SecurityProfile> parse_security_profile(const std::string& yaml_text, const std::string& source,
                                               const std::string& base_dir);
//! Reads a profile and checks that each of its six files can be read (so a typo is reported by name,
//! not as a failed DDS handshake).
Result<SecurityProfile> read_security_profile(const std::string& path);
//! One line per document, for start-up echoes.
std::string describe(const SecurityProfile& profile);

}  // namespace tetra::service
