#include "immerse/parallel/Communicator.hpp"

#include <stdexcept>
#include <string>

namespace immerse {

void check_mpi(int code, const char* what) {
  if (code != MPI_SUCCESS) throw std::runtime_error(std::string("MPI error in ") + what);
}

int Communicator::rank() const {
  int r = 0;
  check_mpi(MPI_Comm_rank(comm_, &r), "MPI_Comm_rank");
  return r;
}

int Communicator::size() const {
  int s = 0;
  check_mpi(MPI_Comm_size(comm_, &s), "MPI_Comm_size");
  return s;
}

void Communicator::barrier() const { check_mpi(MPI_Barrier(comm_), "MPI_Barrier"); }

double Communicator::sum(double x) const { return sum(std::span<const double>(&x, 1))[0]; }

std::vector<double> Communicator::sum(std::span<const double> x) const {
  const int p = size(), n = static_cast<int>(x.size());
  std::vector<double> all(rank() == 0 ? x.size() * p : 0);
  check_mpi(MPI_Gather(x.data(), n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, 0, comm_), "MPI_Gather");
  std::vector<double> total(x.size(), 0.0);
  if (rank() == 0) {
    for (int r = 0; r < p; ++r)
      for (int i = 0; i < n; ++i) total[i] += all[static_cast<std::size_t>(r) * n + i];
  }
  check_mpi(MPI_Bcast(total.data(), n, MPI_DOUBLE, 0, comm_), "MPI_Bcast");
  return total;
}

std::vector<double> Communicator::all_gather(std::span<const double> x) const {
  const int p = size();
  int n = static_cast<int>(x.size());
  std::vector<int> counts(p), offsets(p, 0);
  check_mpi(MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_), "MPI_Allgather");
  for (int r = 1; r < p; ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<double> all(static_cast<std::size_t>(offsets[p - 1]) + counts[p - 1]);
  check_mpi(MPI_Allgatherv(x.data(), n, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, comm_),
        "MPI_Allgatherv");
  return all;
}

}  // namespace immerse
