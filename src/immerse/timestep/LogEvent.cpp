#include "immerse/timestep/LogEvent.hpp"

#include <array>

namespace immerse {
namespace {

constexpr std::array<const char*, 6> kNames{"MembraneForces", "ContactForces", "Spreading", "FluidStep",
                                            "Interpolation", "ImplicitResidual"};

// Registered at the first event logged: logging is on only between PetscInitialize and PetscFinalize, and a process
// initializes PETSc once (PetscSession).
const std::array<PetscLogEvent, kNames.size()>& events() {
  static const auto ids = [] {
    std::array<PetscLogEvent, kNames.size()> e{};
    PetscClassId immerse = 0;
    PetscClassIdRegister("immerse", &immerse);
    for (std::size_t i = 0; i < kNames.size(); ++i) PetscLogEventRegister(kNames[i], immerse, &e[i]);
    return e;
  }();
  return ids;
}

}  // namespace

LogEvent::LogEvent(Phase phase) {
  if (!PetscLogPLB) return;
  event_ = events()[static_cast<std::size_t>(phase)];
  (void)PetscLogEventBegin(event_, 0, 0, 0, 0);
}

LogEvent::~LogEvent() {
  if (event_ >= 0) (void)PetscLogEventEnd(event_, 0, 0, 0, 0);
}

}  // namespace immerse
