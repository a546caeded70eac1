#include "immerse/scenario/ScenarioRun.hpp"

#include "immerse/scenario/ChannelRun.hpp"
#include "immerse/scenario/StretchSweepRun.hpp"
#include "immerse/scenario/SuspensionShearRun.hpp"
#include "immerse/scenario/TubeFlowRun.hpp"
#include "immerse/scenario/CapsuleConstrictionRun.hpp"

namespace immerse {

std::unique_ptr<ScenarioRun> make_scenario_run(const io::Config& config) {
  const std::string kind = config.get<std::string>("scenario.kind");
  if (kind == "rbc_stretch") return std::make_unique<StretchSweepRun>();
  if (kind == "rbc_channel") return std::make_unique<ChannelRun>();
  if (kind == "suspension_shear") return std::make_unique<SuspensionShearRun>(config);
  if (kind == "tube_flow") return std::make_unique<TubeFlowRun>();
  if (kind == "capsule_constriction") return std::make_unique<CapsuleConstrictionRun>();
  return std::make_unique<ScenarioRun>();
}

}  // namespace immerse
