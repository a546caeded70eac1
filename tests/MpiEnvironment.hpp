#pragma once
// Starts MPI (and ends FFTW-MPI and MPI) once for a test program that ctest runs through mpiexec.
#include <fftw3-mpi.h>
#include <gtest/gtest.h>
#include <mpi.h>

namespace immerse::testing {

class MpiEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    int started = 0;
    MPI_Initialized(&started);
    if (!started) MPI_Init(nullptr, nullptr);
  }
  void TearDown() override {
    fftw_mpi_cleanup();
    MPI_Finalize();
  }
};

inline ::testing::Environment* const mpi_environment = ::testing::AddGlobalTestEnvironment(new MpiEnvironment);

}  // namespace immerse::testing
