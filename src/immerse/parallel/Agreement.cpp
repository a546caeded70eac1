#include "immerse/parallel/Agreement.hpp"

#include <stdexcept>

namespace immerse {

std::string broadcast_text(const Communicator& comm, std::string text, int root) {
  unsigned long long n = text.size();
  check_mpi(MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, root, comm.comm()), "MPI_Bcast");
  text.resize(n);
  if (n > 0) check_mpi(MPI_Bcast(text.data(), static_cast<int>(n), MPI_CHAR, root, comm.comm()), "MPI_Bcast");
  return text;
}

std::string first_error(const Communicator& comm, const std::string& error) {
  int mine = error.empty() ? comm.size() : comm.rank(), first = 0;
  check_mpi(MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm.comm()), "MPI_Allreduce");
  if (first == comm.size()) return {};
  return broadcast_text(comm, error, first);
}

int max_over_processes(const Communicator& comm, int value) {
  int result = 0;
  check_mpi(MPI_Allreduce(&value, &result, 1, MPI_INT, MPI_MAX, comm.comm()), "MPI_Allreduce");
  return result;
}

double min_over_processes(const Communicator& comm, double value) {
  double result = 0;
  check_mpi(MPI_Allreduce(&value, &result, 1, MPI_DOUBLE, MPI_MIN, comm.comm()), "MPI_Allreduce");
  return result;
}

}  // namespace immerse
