#pragma once
// A DDS Security profile's six documents (docs/reliability.md): plain data, below both the service,
// which reads profiles (tetra/service/security_profile.hpp), and the DDS layer, which turns them into
// participant QoS properties.

#include <string>

namespace tetra::service {

struct SecurityProfile {
  std::string identity_ca;           //!< PEM: identity certificate authority
  std::string identity_certificate;  //!< PEM: this participant's identity, signed by identity_ca
  std::string private_key;           //!< PEM: the identity's private key
  std::string permissions_ca;        //!< PEM: permissions certificate authority
  std::string governance;            //!< S/MIME-signed governance XML (.p7s)
  std::string permissions;           //!< S/MIME-signed permissions XML (.p7s)
  std::string source;                //!< the profile file, for messages
};

}  // namespace tetra::service
