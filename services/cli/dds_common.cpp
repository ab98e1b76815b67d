#include "dds_common.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "tetra/core/json.hpp"
#include "tetra/dds/entity.hpp"
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

std::string self_executable() {
  return std::filesystem::read_symlink("/proc/self/exe").string();
}

#ifndef TETRA_WEB_DIR
#define TETRA_WEB_DIR "web"
#endif

std::string default_web_dir() {
  const std::filesystem::path installed =
      std::filesystem::path(self_executable()).parent_path() / ".." / "share" / "tetra" / "web";
  std::error_code ec;
  if (std::filesystem::is_directory(installed, ec)) return installed.lexically_normal().string();
  return TETRA_WEB_DIR;
}

int spawn_self(const std::vector<std::string>& args, const std::string& stdout_path,
               const std::string& stderr_path) {
  const std::string exe = self_executable();
  std::vector<std::string> storage;
  storage.push_back(exe);
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid != 0) return pid;  // parent (or -1)
  // Child: signal mask and redirections, then exec. Only async-signal-safe calls from here on.
  // The child is stopped (SIGTERM) when the process that started it ends, however it ends: a campaign
  // worker or a demo killed by a signal leaves no service behind.
  prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (getppid() != parent) _exit(127);  // it ended before the line above
  sigset_t set;
  sigemptyset(&set);
  sigprocmask(SIG_SETMASK, &set, nullptr);
  if (!stdout_path.empty()) {
    const int fd = open(stdout_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) dup2(fd, STDOUT_FILENO);
  }
  if (!stderr_path.empty()) {
    const int fd = open(stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) dup2(fd, STDERR_FILENO);
  }
  execv(exe.c_str(), argv.data());
  _exit(127);
}

}  // namespace tetra::cli
