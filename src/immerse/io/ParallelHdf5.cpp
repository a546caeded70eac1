#include "immerse/io/ParallelHdf5.hpp"

#include <memory>

#include "immerse/core/Error.hpp"
#include "immerse/io/AtomicFile.hpp"
#include "immerse/parallel/Agreement.hpp"

namespace immerse::io::phdf5 {

hdf5::Handle create_file(const std::string& path, MPI_Comm comm) {
  hdf5::Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!fapl.valid() || H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_LATEST) < 0 ||
      H5Pset_fapl_mpio(fapl.get(), comm, MPI_INFO_NULL) < 0)
    return {};
  return {H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), H5Fclose};
}

bool write_rows(hid_t loc, const std::string& name, hid_t file_type, hid_t mem_type, const std::vector<hsize_t>& dims,
                std::span<const Rows> rows, const void* data) {
  hdf5::Handle space(
      dims.empty() ? H5Screate(H5S_SCALAR) : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
      H5Sclose);
  if (!space.valid()) return false;
  hdf5::Handle set(H5Dcreate2(loc, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                   H5Dclose);
  // The selection in the file and the elements this process writes; a failure is remembered, not returned early,
  // so that every process still takes part in the collective write.
  bool ok = set.valid();
  hsize_t elements = 0;
  if (dims.empty()) {
    ok = ok && (rows.empty() ? H5Sselect_none(space.get()) : H5Sselect_all(space.get())) >= 0;
    elements = rows.empty() ? 0 : 1;
  } else {
    hsize_t row_size = 1;
    for (std::size_t d = 1; d < dims.size(); ++d) row_size *= dims[d];
    ok = ok && H5Sselect_none(space.get()) >= 0;
    std::vector<hsize_t> start(dims.size(), 0), count(dims);
    for (const Rows& r : rows) {
      if (r.count == 0) continue;
      start[0] = r.first;
      count[0] = r.count;
      ok = ok && H5Sselect_hyperslab(space.get(), H5S_SELECT_OR, start.data(), nullptr, count.data(), nullptr) >= 0;
      elements += r.count * row_size;
    }
  }
  const hsize_t mem_dims = elements > 0 ? elements : 1;
  hdf5::Handle mem(H5Screate_simple(1, &mem_dims, nullptr), H5Sclose);
  ok = ok && mem.valid() && (elements > 0 ? H5Sselect_all(mem.get()) : H5Sselect_none(mem.get())) >= 0;
  hdf5::Handle xfer(H5Pcreate(H5P_DATASET_XFER), H5Pclose);
  ok = ok && xfer.valid() && H5Pset_dxpl_mpio(xfer.get(), H5FD_MPIO_COLLECTIVE) >= 0;
  static const double dummy = 0;  // HDF5 rejects a null buffer even for zero elements
  hsize_t total = 1;
  for (const hsize_t d : dims) total *= d;
  if (set.valid() && mem.valid() && xfer.valid() && total > 0)  // an empty dataset has nothing to write
    ok = H5Dwrite(set.get(), mem_type, mem.get(), space.get(), xfer.get(), elements > 0 ? data : &dummy) >= 0 && ok;
  return set.close() && ok;
}

bool write_doubles(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims, std::span<const Rows> rows,
                   const double* data) {
  return write_rows(loc, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, dims, rows, data);
}
bool write_int32(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims, std::span<const Rows> rows,
                 const std::int32_t* data) {
  return write_rows(loc, name, H5T_STD_I32LE, H5T_NATIVE_INT32, dims, rows, data);
}
bool write_int64(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims, std::span<const Rows> rows,
                 const std::int64_t* data) {
  return write_rows(loc, name, H5T_STD_I64LE, H5T_NATIVE_INT64, dims, rows, data);
}

bool write_string(hid_t loc, const std::string& name, const std::string& value, bool writer) {
  // As hdf5::write_string: a fixed-length, NUL-padded string of at least one byte.
  hdf5::Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  if (!type.valid() || H5Tset_size(type.get(), value.empty() ? 1 : value.size()) < 0 ||
      H5Tset_strpad(type.get(), H5T_STR_NULLPAD) < 0)
    return false;
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  const Rows all{0, 1};
  return write_rows(loc, name, type.get(), type.get(), {},
                    writer ? std::span<const Rows>(&all, 1) : std::span<const Rows>(), padded.data());
}

void write_file_atomically(const std::filesystem::path& path, const Communicator& comm,
                           const std::function<std::string(hid_t file)>& fill) {
  const bool root = comm.rank() == 0;
  std::unique_ptr<AtomicFile> on_root;  // removes the temporary unless committed
  if (root) on_root = std::make_unique<AtomicFile>(path);
  const std::string temp = broadcast_text(comm, root ? on_root->temp_path().string() : std::string());
  std::string error;
  {
    hdf5::Quiet quiet;
    hdf5::Handle file = create_file(temp, comm.comm());
    if (!file.valid()) {
      error = "HDF5 error creating the file";
    } else {
      error = fill(file.get());
      if (!file.close() && error.empty()) error = "HDF5 error closing the file";
    }
  }
  error = first_error(comm, error);
  if (!error.empty()) error = "cannot write " + path.string() + ": " + error;
  if (root && error.empty()) try {
      on_root->commit();
    } catch (const WriteError& e) {
      error = e.what();
    }
  error = broadcast_text(comm, error);
  if (!error.empty()) throw WriteError(error);
}

}  // namespace immerse::io::phdf5
