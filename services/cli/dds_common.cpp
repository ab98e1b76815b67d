#include "dds_common.hpp"

#include <filesystem>

#include "tetra/core/json.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds_tools/child_process.hpp"
#include "tetra/service/security_profile.hpp"
#include "tetra/service/unit_name.hpp"

namespace tetra::cli {

CLI::Validator unit_name_check() {
  return CLI::Validator(
      [](const std::string& name) {
        const Status status = service::check_unit_name(name, "unit name");
        return status ? std::string() : status.error().message;
      },
      "UNIT");
}

void add_domain_option(CLI::App& app, dds_domainid_t& domain) {
  domain = DDS_DOMAIN_DEFAULT;
  app.add_option("--domain", domain, "DDS domain id (default: the Cyclone configuration's, normally 0)")
      ->check(CLI::Range(0, 232));
  // Opt-in DDS Security (docs/reliability.md): the participant's identity and permissions.
  app.add_option_function<std::string>(
      "--security",
      [](const std::string& path) {
        auto profile = service::read_security_profile(path);
        if (!profile) throw CLI::ValidationError("--security", profile.error().message);
        dds::set_security_profile(std::move(profile).value());
      },
      "DDS Security profile YAML of this participant's role (scripts/security/make_pki.sh)");
  // Every type is @final: its writers can send either encoding (docs/dds.md, "Data representation").
  app.add_option_function<std::string>(
         "--data-representation",
         [](const std::string& name) {
           dds::set_data_representation(name == "xcdr2" ? dds::DataRepresentation::kXcdr2
                                                        : dds::DataRepresentation::kXcdr1);
         },
         "CDR encoding of this process's writers: xcdr1 (default; every DDS-XTypes reader accepts it) or "
         "xcdr2 (for XCDR2-only readers); its readers accept both")
      ->check(CLI::IsMember({"xcdr1", "xcdr2"}));
}

#ifndef TETRA_WEB_DIR
#define TETRA_WEB_DIR "web"
#endif

std::string default_web_dir() {
  const std::filesystem::path installed =
      std::filesystem::path(dds_tools::self_executable()).parent_path() / ".." / "share" / "tetra" / "web";
  std::error_code ec;
  if (std::filesystem::is_directory(installed, ec)) return installed.lexically_normal().string();
  return TETRA_WEB_DIR;
}

}  // namespace tetra::cli
