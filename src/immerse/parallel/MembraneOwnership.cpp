#include "immerse/parallel/MembraneOwnership.hpp"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "immerse/coupling/IndexAxis.hpp"

namespace immerse {

namespace {

void append(std::vector<double>& out, std::span<const Vec3> X) {
  for (const Vec3& x : X) out.insert(out.end(), {x[0], x[1], x[2]});
}

std::vector<Vec3> read(const double* in, int n) {
  std::vector<Vec3> X(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) X[i] = Vec3{in[3 * i], in[3 * i + 1], in[3 * i + 2]};
  return X;
}

/// out[r] sent to process r; returns what every process sent to this one, in rank order (one MPI_Alltoall of the
/// counts, one MPI_Alltoallv). Collective.
std::vector<double> all_to_all(const Communicator& comm, const std::vector<std::vector<double>>& out) {
  const int size = comm.size();
  std::vector<int> send_counts(size), send_offsets(size, 0), recv_counts(size), recv_offsets(size, 0);
  for (int r = 0; r < size; ++r) send_counts[r] = static_cast<int>(out[r].size());
  check_mpi(MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, comm.comm()), "MPI_Alltoall");
  for (int r = 1; r < size; ++r) {
    send_offsets[r] = send_offsets[r - 1] + send_counts[r - 1];
    recv_offsets[r] = recv_offsets[r - 1] + recv_counts[r - 1];
  }
  std::vector<double> send, recv(static_cast<std::size_t>(recv_offsets[size - 1]) + recv_counts[size - 1]);
  for (const std::vector<double>& o : out) send.insert(send.end(), o.begin(), o.end());
  check_mpi(MPI_Alltoallv(send.data(), send_counts.data(), send_offsets.data(), MPI_DOUBLE, recv.data(),
                      recv_counts.data(), recv_offsets.data(), MPI_DOUBLE, comm.comm()),
        "MPI_Alltoallv");
  return recv;
}

}  // namespace

MembraneOwnership::MembraneOwnership(const SlabDecomposition& slabs, std::span<const std::vector<Vec3>> positions,
                                     std::span<const std::vector<Vec3>> reference)
    : slabs_(slabs) {
  if (positions.size() != reference.size())
    throw std::invalid_argument("MembraneOwnership: the positions and reference positions of " +
                                std::to_string(positions.size()) + " and " + std::to_string(reference.size()) +
                                " membranes");
  const int rank = slabs_.communicator().rank();
  std::size_t offset = 0;
  for (std::size_t m = 0; m < positions.size(); ++m) {
    if (positions[m].empty() || positions[m].size() != reference[m].size())
      throw std::invalid_argument("MembraneOwnership: membrane " + std::to_string(m) + " has " +
                                  std::to_string(positions[m].size()) + " positions and " +
                                  std::to_string(reference[m].size()) + " reference positions");
    node_counts_.push_back(static_cast<int>(positions[m].size()));
    node_offsets_.push_back(offset);
    offset += positions[m].size();
    if (owner(positions[m]) == rank) owned_.push_back({static_cast<int>(m), positions[m], reference[m]});
  }
  for (const OwnedMembrane& m : owned_) moves_.push_back({m.id, rank});
}

Vec3 MembraneOwnership::centroid(std::span<const Vec3> X) {
  Vec3 sum{};
  for (const Vec3& x : X) sum = sum + x;
  return sum / static_cast<double>(X.size());
}

int MembraneOwnership::owner(std::span<const Vec3> X) const {
  const Grid& g = slabs_.grid();
  const double t = IndexAxis(g, 2).face_coordinate(centroid(X)[2]);
  const int cell = std::clamp(static_cast<int>(std::floor(t)), 0, g.n(2) - 1);
  return cell / slabs_.block();
}

std::size_t MembraneOwnership::num_owned_nodes() const {
  std::size_t n = 0;
  for (const OwnedMembrane& m : owned_) n += m.positions.size();
  return n;
}

std::vector<Vec3> MembraneOwnership::owned_positions() const {
  std::vector<Vec3> X;
  X.reserve(num_owned_nodes());
  for (const OwnedMembrane& m : owned_) X.insert(X.end(), m.positions.begin(), m.positions.end());
  return X;
}

void MembraneOwnership::set_owned_positions(std::span<const Vec3> X) {
  if (X.size() != num_owned_nodes())
    throw std::invalid_argument("MembraneOwnership::set_owned_positions: " + std::to_string(X.size()) +
                                " positions for " + std::to_string(num_owned_nodes()) + " owned nodes");
  std::size_t at = 0;
  for (OwnedMembrane& m : owned_) {
    std::copy_n(X.begin() + static_cast<std::ptrdiff_t>(at), m.positions.size(), m.positions.begin());
    at += m.positions.size();
  }
}

int MembraneOwnership::migrate() {
  const Communicator& comm = slabs_.communicator();
  const int size = comm.size(), rank = comm.rank();
  // Per destination: index, then positions and reference positions (3 n_m values each) of each leaving membrane.
  std::vector<std::vector<double>> out(static_cast<std::size_t>(size));
  std::vector<OwnedMembrane> staying;
  moves_.clear();
  for (OwnedMembrane& m : owned_) {
    const int to = owner(m.positions);
    moves_.push_back({m.id, to});
    if (to == rank) {
      staying.push_back(std::move(m));
      continue;
    }
    std::vector<double>& o = out[to];
    o.push_back(static_cast<double>(m.id));
    append(o, m.positions);
    append(o, m.reference);
  }
  const int leaving = static_cast<int>(owned_.size() - staying.size());
  owned_ = std::move(staying);

  const std::vector<double> recv = all_to_all(comm, out);
  for (std::size_t at = 0; at < recv.size();) {
    const int id = static_cast<int>(recv[at]);
    const int n = node_counts_.at(static_cast<std::size_t>(id));
    OwnedMembrane m{id, read(recv.data() + at + 1, n), read(recv.data() + at + 1 + 3 * static_cast<std::size_t>(n), n)};
    owned_.push_back(std::move(m));
    at += 1 + 6 * static_cast<std::size_t>(n);
  }
  std::sort(owned_.begin(), owned_.end(), [](const OwnedMembrane& a, const OwnedMembrane& b) { return a.id < b.id; });
  return static_cast<int>(comm.sum(static_cast<double>(leaving)));
}

std::vector<double> MembraneOwnership::follow(std::span<const double> before, std::size_t arrays) const {
  const Communicator& comm = slabs_.communicator();
  const int size = comm.size(), rank = comm.rank();
  std::size_t nodes_before = 0;
  for (const Move& m : moves_) nodes_before += static_cast<std::size_t>(node_counts_[m.id]);
  if (before.size() != arrays * 3 * nodes_before)
    throw std::invalid_argument("MembraneOwnership::follow: " + std::to_string(before.size()) + " values for " +
                                std::to_string(arrays) + " arrays over " + std::to_string(nodes_before) + " nodes");
  const std::size_t stride = 3 * nodes_before;  // between the arrays of `before`
  // Where each membrane's values begin in the first array: staying ones in `before`, arriving ones in `recv`.
  std::vector<const double*> from(node_counts_.size(), nullptr);
  std::vector<std::size_t> step(node_counts_.size(), 0);  // from one array to the next
  std::vector<std::vector<double>> out(static_cast<std::size_t>(size));
  std::size_t at = 0;
  for (const Move& m : moves_) {
    const std::size_t n = 3 * static_cast<std::size_t>(node_counts_[m.id]);
    if (m.to == rank) {
      from[m.id] = before.data() + at;
      step[m.id] = stride;
    } else {
      std::vector<double>& o = out[m.to];
      o.push_back(static_cast<double>(m.id));
      for (std::size_t a = 0; a < arrays; ++a) {
        const auto first = before.begin() + static_cast<std::ptrdiff_t>(a * stride + at);
        o.insert(o.end(), first, first + static_cast<std::ptrdiff_t>(n));
      }
    }
    at += n;
  }
  const std::vector<double> recv = all_to_all(comm, out);
  for (std::size_t q = 0; q < recv.size();) {
    const auto id = static_cast<std::size_t>(recv[q]);
    const std::size_t n = 3 * static_cast<std::size_t>(node_counts_.at(id));
    from[id] = recv.data() + q + 1;
    step[id] = n;
    q += 1 + arrays * n;
  }
  const std::size_t nodes_now = num_owned_nodes();
  std::vector<double> now(arrays * 3 * nodes_now);
  at = 0;
  for (const OwnedMembrane& m : owned_) {
    const std::size_t n = 3 * m.positions.size();
    if (!from[m.id])
      throw std::logic_error("MembraneOwnership::follow: no values for membrane " + std::to_string(m.id));
    for (std::size_t a = 0; a < arrays; ++a)
      std::copy_n(from[m.id] + a * step[m.id], n, now.begin() + static_cast<std::ptrdiff_t>(a * 3 * nodes_now + at));
    at += n;
  }
  return now;
}

std::vector<Vec3> MembraneOwnership::gather(std::span<const Vec3> owned_values) const {
  if (owned_values.size() != num_owned_nodes())
    throw std::invalid_argument("MembraneOwnership::gather: " + std::to_string(owned_values.size()) +
                                " values for " + std::to_string(num_owned_nodes()) + " owned nodes");
  std::vector<double> mine;
  std::size_t at = 0;
  for (const OwnedMembrane& m : owned_) {
    mine.push_back(static_cast<double>(m.id));
    append(mine, owned_values.subspan(at, m.positions.size()));
    at += m.positions.size();
  }
  const std::vector<double> all = slabs_.communicator().all_gather(mine);
  std::vector<Vec3> values(node_offsets_.empty() ? 0 : node_offsets_.back() + node_counts_.back());
  std::vector<int> seen(node_counts_.size(), 0);
  for (std::size_t q = 0; q < all.size();) {
    const auto id = static_cast<std::size_t>(all[q]);
    const int n = node_counts_.at(id);
    const std::vector<Vec3> v = read(all.data() + q + 1, n);
    std::copy(v.begin(), v.end(), values.begin() + static_cast<std::ptrdiff_t>(node_offsets_[id]));
    ++seen[id];
    q += 1 + 3 * static_cast<std::size_t>(n);
  }
  if (std::any_of(seen.begin(), seen.end(), [](int s) { return s != 1; }))
    throw std::logic_error("MembraneOwnership::gather: a membrane is not owned by exactly one process");
  return values;
}

std::vector<std::vector<Vec3>> MembraneOwnership::gather_positions() const {
  const std::vector<Vec3> all = gather(owned_positions());
  std::vector<std::vector<Vec3>> X(node_counts_.size());
  for (std::size_t m = 0; m < X.size(); ++m) {
    const auto begin = all.begin() + static_cast<std::ptrdiff_t>(node_offsets_[m]);
    X[m].assign(begin, begin + node_counts_[m]);
  }
  return X;
}

}  // namespace immerse
