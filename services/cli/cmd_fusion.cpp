// tetra fusion --config CFG.yaml — the fusion pipeline as a DDS service (docs/dds.md); the service
// itself is service::FusionService (tetra/service/fusion_service.hpp).

#include <spdlog/spdlog.h>

#include <optional>

#include "cli_common.hpp"
#include "commands.hpp"
#include "dds_common.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/fdi/noise_defaults.hpp"
#include "tetra/fdi/pipeline.hpp"
#include "tetra/service/fusion_config.hpp"
#include "tetra/service/fusion_service.hpp"
#include "tetra/service/realtime.hpp"

namespace tetra::cli {

int cmd_fusion(int argc, char** argv) {
  dds::ShutdownSignal shutdown;  // first: DDS threads must inherit the blocked signals
  CLI::App app{"The fusion service on DDS: gyro samples in; attitude, health and FDI events out.", "fusion"};
  std::string config_path;
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;
  std::string log_level = "info";
  std::optional<int> realtime_priority;
  app.add_option("--config", config_path, "service configuration YAML (docs/dds.md)")->required();
  add_domain_option(app, domain);
  app.add_option("--log-level", log_level, "spdlog level: trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
  app.add_option("--realtime", realtime_priority,
                 "lock the memory (mlockall) and run the threads that receive gyro samples and step the "
                 "pipeline under SCHED_FIFO at this priority (1..99; docs/dds.md, \"Real-time scheduling\"); "
                 "what the system does not allow (no privilege) is warned about and the service runs on")
      ->check(CLI::Range(service::kMinRealtimePriority, service::kMaxRealtimePriority));
  if (auto exit = parse(app, argc, argv)) return *exit;
  spdlog::set_level(spdlog::level::from_str(log_level));
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");

  auto config = service::read_fusion_config(config_path);
  if (!config) return report("fusion", config.error());
  config->realtime_priority = realtime_priority;
  if (config->security) dds::set_security_profile(config->security);
  auto pipeline = fdi::Pipeline::create(config->calibration, config->pipeline);
  if (!pipeline) return report("fusion", pipeline.error());
  if (const std::string w = fdi::default_noise_warning(config->calibration, config->pipeline); !w.empty())
    spdlog::warn("fusion: calibration: {}", w);
  auto assembler = service::EpochAssembler::create(config->assembler(pipeline->gyro_count()));
  if (!assembler) return report("fusion", assembler.error());
  spdlog::info("fusion: configuration from {}\n{}", config_path, service::describe(*config));

  service::FusionService service(std::move(config).value(), std::move(pipeline).value(),
                                 std::move(assembler).value());
  if (auto s = service.open(domain, &shutdown); !s) return report("fusion", s.error());
  if (auto s = service.run(); !s) return report("fusion", s.error());
  spdlog::info("fusion: stopped");
  return kExitOk;
}

}  // namespace tetra::cli
