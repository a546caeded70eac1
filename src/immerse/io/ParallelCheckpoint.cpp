#include "immerse/io/ParallelCheckpoint.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>

#include "immerse/io/Checkpoint.hpp"
#include "immerse/io/Fnv1a64.hpp"
#include "immerse/io/ParallelHdf5.hpp"

namespace immerse::io {

void ParallelCheckpoint::check_new_name(const std::string& name) const {
  if (name.empty() || name == "." || name.find('/') != std::string::npos)
    throw std::logic_error("checkpoint: bad entry name '" + name + "'");
  if (arrays_.contains(name) || ints_.contains(name) || doubles_.contains(name) || strings_.contains(name))
    throw std::logic_error("checkpoint: entry '" + name + "' is already set");
}

void ParallelCheckpoint::put_array(const std::string& name, std::vector<std::size_t> shape, std::vector<Piece> pieces) {
  check_new_name(name);
  Array a;
  a.size = std::accumulate(shape.begin(), shape.end(), std::size_t{1}, std::multiplies<>());
  a.shape = std::move(shape);
  std::erase_if(pieces, [](const Piece& p) { return p.values.empty(); });
  std::ranges::sort(pieces, {}, &Piece::offset);
  for (const Piece& p : pieces)
    if (p.offset + p.values.size() > a.size)
      throw std::logic_error("checkpoint: a piece of '" + name + "' is outside it");
  a.pieces = std::move(pieces);
  arrays_[name] = std::move(a);
}
void ParallelCheckpoint::put_int(const std::string& name, std::int64_t value) {
  check_new_name(name);
  ints_[name] = value;
}
void ParallelCheckpoint::put_double(const std::string& name, double value) {
  check_new_name(name);
  doubles_[name] = value;
}
void ParallelCheckpoint::put_string(const std::string& name, std::string value) {
  check_new_name(name);
  strings_[name] = std::move(value);
}

std::uint64_t ParallelCheckpoint::checksum() const {
  const int rank = comm_.rank();
  // Where every piece is: (array number, offset, size, rank) of all processes, in one gather.
  std::vector<double> mine;
  std::size_t number = 0;
  for (const auto& [name, a] : arrays_) {
    for (const Piece& p : a.pieces)
      mine.insert(mine.end(), {double(number), double(p.offset), double(p.values.size()), double(rank)});
    ++number;
  }
  const std::vector<double> all = comm_.all_gather(mine);
  struct Segment {
    std::size_t offset, size;
    int rank;
  };
  std::vector<std::vector<Segment>> segments(arrays_.size());
  for (std::size_t q = 0; q + 4 <= all.size(); q += 4)
    segments[static_cast<std::size_t>(all[q])].push_back(
        {static_cast<std::size_t>(all[q + 1]), static_cast<std::size_t>(all[q + 2]), static_cast<int>(all[q + 3])});
  // Every process follows the same sequence; the state is only right on the process holding it, which hands it on.
  Fnv1a64 h;
  int holder = 0;
  const auto hand_to = [&](int next) {
    if (next == holder) return;
    std::uint64_t state = h.value();
    if (rank == holder) check_mpi(MPI_Send(&state, 1, MPI_UINT64_T, next, 0, comm_.comm()), "MPI_Send");
    if (rank == next)
      check_mpi(MPI_Recv(&state, 1, MPI_UINT64_T, holder, 0, comm_.comm(), MPI_STATUS_IGNORE), "MPI_Recv");
    h = Fnv1a64(state);
    holder = next;
  };
  number = 0;
  for (const auto& [name, a] : arrays_) {
    h.text("array:" + name);
    h.u64(a.shape.size());
    for (const auto d : a.shape) h.u64(d);
    h.u64(a.size);
    auto& segs = segments[number++];
    std::ranges::sort(segs, {}, &Segment::offset);
    std::size_t next = 0;
    for (const Segment& s : segs) {
      if (s.offset != next) throw std::logic_error("checkpoint: the pieces of '" + name + "' do not tile it");
      next += s.size;
      hand_to(s.rank);
      if (rank == s.rank) {
        const auto it = std::ranges::find(a.pieces, s.offset, &Piece::offset);
        h.bytes(it->values.data(), it->values.size() * sizeof(double));
      }
    }
    if (next != a.size) throw std::logic_error("checkpoint: the pieces of '" + name + "' do not tile it");
  }
  hand_to(0);
  for (const auto& [name, v] : ints_) {
    h.text("int:" + name);
    h.bytes(&v, sizeof v);
  }
  for (const auto& [name, v] : doubles_) {
    h.text("double:" + name);
    h.bytes(&v, sizeof v);
  }
  for (const auto& [name, v] : strings_) {
    h.text("string:" + name);
    h.text(v);
  }
  std::uint64_t result = h.value();
  check_mpi(MPI_Bcast(&result, 1, MPI_UINT64_T, 0, comm_.comm()), "MPI_Bcast");
  return result;
}

void ParallelCheckpoint::write(const std::filesystem::path& path) const {
  const bool root = comm_.rank() == 0;
  const std::uint64_t sum = checksum();
  phdf5::write_file_atomically(path, comm_, [&](hid_t file) {
    std::string error;
    const auto check = [&](bool ok, const std::string& what) {
      if (!ok && error.empty()) error = "HDF5 error writing " + what;
    };
    check(hdf5::write_attribute(file, "immerse_checkpoint_format", Checkpoint::kFormatVersion), "format version");
    check(hdf5::write_attribute(file, "checksum_fnv1a64", sum), "checksum");
    for (const auto& [name, value] : attributes_) check(hdf5::write_attribute(file, name, value), name);
    hdf5::Handle arrays = hdf5::create_group(file, "arrays");
    hdf5::Handle ints = hdf5::create_group(file, "int64");
    hdf5::Handle doubles = hdf5::create_group(file, "double");
    hdf5::Handle strings = hdf5::create_group(file, "string");
    check(arrays.valid() && ints.valid() && doubles.valid() && strings.valid(), "groups");
    for (const auto& [name, a] : arrays_) {
      std::vector<phdf5::Rows> rows;
      std::vector<double> values;
      for (const Piece& p : a.pieces) {
        rows.push_back({p.offset, p.values.size()});
        values.insert(values.end(), p.values.begin(), p.values.end());
      }
      check(phdf5::write_doubles(arrays.get(), name, {a.size}, rows, values.data()), "arrays/" + name);
      hdf5::Handle set(H5Dopen2(arrays.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
      check(set.valid() &&
                hdf5::write_attribute(set.get(), "shape", std::vector<std::int64_t>(a.shape.begin(), a.shape.end())),
            "arrays/" + name + " shape");
    }
    const phdf5::Rows one{0, 1};
    const auto writer = root ? std::span<const phdf5::Rows>(&one, 1) : std::span<const phdf5::Rows>();
    for (const auto& [name, v] : ints_) check(phdf5::write_int64(ints.get(), name, {}, writer, &v), "int64/" + name);
    for (const auto& [name, v] : doubles_)
      check(phdf5::write_doubles(doubles.get(), name, {}, writer, &v), "double/" + name);
    for (const auto& [name, v] : strings_) check(phdf5::write_string(strings.get(), name, v, root), "string/" + name);
    check(arrays.close() && ints.close() && doubles.close() && strings.close(), "groups");
    return error;
  });
}

}  // namespace immerse::io
