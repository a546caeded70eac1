#pragma once
// A group of MPI processes: rank, size, barrier, and reductions whose result does not depend on MPI.
//
// sum(x) = ((x_0 + x_1) + x_2) + … + x_{P−1}, the values of ranks 0 … P−1 added on rank 0 in rank order and then
// broadcast: the same bits on every rank and in every run with P processes, whatever reduction tree the MPI library
// would choose (MPI_Allreduce may associate the additions differently from one call or library version to the next).
//
// A value type around an MPI_Comm it does not own (copying copies the handle; the program creates and frees
// communicators). MPI_Init and MPI_Finalize belong to the program, not to this class.
// Verified by: the tests Communicator.* of tests/test_parallel_slab_solver.cpp (run with 1, 2 and 3 processes).
#include <mpi.h>

#include <span>
#include <vector>

namespace immerse {

/// Throws std::runtime_error naming the MPI call `what` unless `code` is MPI_SUCCESS.
void check_mpi(int code, const char* what);

class Communicator {
 public:
  /// The group of every process of the program (MPI_COMM_WORLD).
  static Communicator world() { return Communicator(MPI_COMM_WORLD); }
  explicit Communicator(MPI_Comm comm) : comm_(comm) {}

  MPI_Comm comm() const { return comm_; }
  int rank() const;
  int size() const;
  void barrier() const;

  /// The sum over ranks of x, added in rank order on rank 0 and broadcast to every rank.
  double sum(double x) const;
  /// Element-wise sum over ranks of equally long arrays, added in rank order (same on every rank).
  std::vector<double> sum(std::span<const double> x) const;
  /// The arrays of every rank, concatenated in rank order, on every rank (the lengths may differ).
  std::vector<double> all_gather(std::span<const double> x) const;

 private:
  MPI_Comm comm_;
};

}  // namespace immerse
