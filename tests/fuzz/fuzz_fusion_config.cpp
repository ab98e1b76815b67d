// libFuzzer target: the service configuration (`tetra fusion --config`, services/fusion) on arbitrary
// bytes. `calibration: cal.yaml` and `security: sec.yaml` resolve to valid files written once into a
// private directory, so inputs can reach every key; other paths fail as "cannot open".
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>

#include "fuzz_check.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/service/fusion_config.hpp"

namespace {

std::string g_dir;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  char pattern[] = "/tmp/tetra-fuzz-fusion-XXXXXX";
  const char* dir = mkdtemp(pattern);
  if (dir == nullptr) std::abort();
  g_dir = dir;
  if (!tetra::write_calibration(g_dir + "/cal.yaml", tetra::seed_as_built_unit()).ok()) std::abort();
  std::ofstream(g_dir + "/sec.yaml") << "identity_ca: cal.yaml\nidentity_certificate: cal.yaml\n"
                                        "private_key: cal.yaml\npermissions_ca: cal.yaml\n"
                                        "governance: cal.yaml\npermissions: cal.yaml\n";
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const auto config = tetra::service::parse_fusion_config(text, "fuzz.yaml", g_dir);
  if (!config) {
    tetra::fuzz::check_error_message(config.error());
    return 0;
  }
  TETRA_FUZZ_CHECK(tetra::service::validate(*config).ok());
  (void)tetra::service::describe(*config);
  TETRA_FUZZ_CHECK(config->deadline_ns() > 0);
  (void)config->assembler(config->calibration.gyro_count());
  return 0;
}
