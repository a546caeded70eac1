#include "immerse/timestep/PetscSession.hpp"

#include <stdexcept>

namespace immerse {

PetscSession::PetscSession() {
  PetscBool initialized = PETSC_FALSE;
  PetscInitialized(&initialized);
  if (initialized) throw std::logic_error("PetscSession: PETSc is already initialized");
  if (PetscInitializeNoArguments() != 0) throw std::runtime_error("PETSc failed to initialize");
  // Errors come back as codes and become exceptions; nothing is printed by PETSc itself.
  PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
  // PETSc's signal handler prints a crash report and aborts MPI on SIGPIPE, SIGHUP, SIGTERM...: the default
  // dispositions come back, and the program sets its own where it needs them.
  PetscPopSignalHandler();
}

PetscSession::~PetscSession() {
  PetscPopErrorHandler();
  PetscFinalize();
}

void check_petsc(PetscErrorCode ierr, const char* what) {
  if (ierr == 0) return;
  const char* text = nullptr;
  char* specific = nullptr;
  PetscErrorMessage(ierr, &text, &specific);
  std::string msg = std::string("PETSc error in ") + what + ": " + (text ? text : "unknown error");
  if (specific && *specific) msg += std::string(" (") + specific + ")";
  throw std::runtime_error(msg);
}

}  // namespace immerse
