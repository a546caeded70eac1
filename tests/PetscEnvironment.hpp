#pragma once
// Initializes PETSc once for a test program that uses the PETSc-based solvers.
#include <gtest/gtest.h>

#include <memory>

#include "immerse/timestep/PetscSession.hpp"

namespace immerse::testing {

class PetscEnvironment : public ::testing::Environment {
 public:
  void SetUp() override { session_ = std::make_unique<PetscSession>(); }
  void TearDown() override { session_.reset(); }

 private:
  std::unique_ptr<PetscSession> session_;
};

inline ::testing::Environment* const petsc_environment =
    ::testing::AddGlobalTestEnvironment(new PetscEnvironment);

}  // namespace immerse::testing
