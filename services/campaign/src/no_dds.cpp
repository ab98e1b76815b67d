// `target: dds` campaigns in a build without DDS.
#include "tetra/campaign/dds_estimators.hpp"

namespace tetra::campaign {

sim::EstimatorFactory dds_campaign_estimators(const sim::CampaignSpec&, const std::string&) {
  return [](const sim::Scenario&, const sim::CampaignCase&,
            const Quaternion&) -> Result<std::unique_ptr<sim::Estimator>> {
    return failure("target: dds is not available in this build (no DDS)");
  };
}

}  // namespace tetra::campaign
