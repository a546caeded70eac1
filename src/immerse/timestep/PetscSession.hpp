#pragma once
// PETSc (and through it MPI) lifetime. Create one in main() before any PETSc-based solver; it finalizes on
// destruction. PETSc errors are turned into C++ exceptions (check_petsc) instead of printed tracebacks.
#include <petscsys.h>

#include <string>

namespace immerse {

class PetscSession {
 public:
  PetscSession();
  ~PetscSession();
  PetscSession(const PetscSession&) = delete;
  PetscSession& operator=(const PetscSession&) = delete;
};

/// Throws std::runtime_error with PETSc's message when ierr != 0; `what` names the call.
void check_petsc(PetscErrorCode ierr, const char* what);

}  // namespace immerse

#define IMMERSE_PETSC(call) ::immerse::check_petsc((call), #call)
