#include "immerse/run/OutputSchedule.hpp"

namespace immerse {

OutputSchedule OutputSchedule::from(const io::Config& config) {
  OutputSchedule s;
  s.diagnostics_every = config.get<int>("output.diagnostics_every");
  s.fields_every = config.get<int>("output.fields_every");
  s.checkpoint_every = config.get<int>("output.checkpoint_every");
  s.fluid_fields = config.get<bool>("output.fluid_fields");
  s.end_time = config.get<double>("time.end");
  s.log_seconds = config.get<double>("output.log_seconds");
  return s;
}

}  // namespace immerse
