#pragma once
// HDF5 files that the processes of a communicator write together (the MPI-IO driver, H5Pset_fapl_mpio): the file
// and its datasets are created by every process alike, and each process writes its own rows of a dataset (its z
// planes of a fluid array, the nodes of the membranes it owns) with collective I/O. Metadata (groups, attributes)
// is written by every process with the same values, as parallel HDF5 requires. Functions report failure through
// their return value, as those of Hdf5.hpp.
// Verified by: the tests RunMpi.* (tests/test_run_mpi.cpp: frames and checkpoints of 2 and 3 processes read back
// with the one-process readers).
#include <mpi.h>

#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "immerse/io/Hdf5.hpp"
#include "immerse/parallel/Communicator.hpp"

namespace immerse::io::phdf5 {

/// Consecutive rows [first, first + count) along the first dimension of a dataset.
struct Rows {
  hsize_t first = 0, count = 0;
};

/// Creates (or truncates) `path` for writing by every process of `comm`, with the metadata format of the serial
/// files (HDF5 1.8 and later, checksummed). Collective.
hdf5::Handle create_file(const std::string& path, MPI_Comm comm);

/// Creates the dataset `name` with dimensions `dims` (slowest first; empty: a scalar) and writes this process's
/// `rows` of it, ascending and not overlapping, from `data` holding them one after the other (a scalar is written by
/// the processes passing a nonempty `rows`). Collective: every process calls it, with its own rows (possibly none).
bool write_rows(hid_t loc, const std::string& name, hid_t file_type, hid_t mem_type, const std::vector<hsize_t>& dims,
                std::span<const Rows> rows, const void* data);
bool write_doubles(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims, std::span<const Rows> rows,
                   const double* data);
bool write_int32(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims, std::span<const Rows> rows,
                 const std::int32_t* data);
bool write_int64(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims, std::span<const Rows> rows,
                 const std::int64_t* data);
/// A scalar string dataset, written by the process with `writer` true (the others pass the same value). Collective.
bool write_string(hid_t loc, const std::string& name, const std::string& value, bool writer);

/// Writes the file `path` atomically with every process of `comm`: rank 0 names the temporary ("NAME.tmp.PID",
/// AtomicFile), every process opens it (create_file) and `fill` writes the content into it, returning its first
/// failure as a text (empty: none); once every process has closed the file, rank 0 renames it over `path`.
/// WriteError "cannot write PATH: ..." on every process if any failed (the temporary is then removed). Collective.
void write_file_atomically(const std::filesystem::path& path, const Communicator& comm,
                           const std::function<std::string(hid_t file)>& fill);

}  // namespace immerse::io::phdf5
