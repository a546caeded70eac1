#pragma once
// A checkpoint that the processes of a communicator write together into one HDF5 file (ParallelHdf5.hpp), with the
// layout, format version and checksum of Checkpoint, so that Checkpoint::read reads it: a restart on any number of
// processes, or in one process, reads it whole and takes its part.
//
// Arrays are spread over the processes: each passes its pieces (an offset into the flat array and the values from
// there); together the pieces tile the array. Integers, doubles and strings are passed alike by every process and
// written by rank 0.
//
// Checksum: the FNV-1a-64 of Checkpoint::checksum(), over every entry in canonical order, the same number a
// one-process checkpoint of the same content has. FNV is sequential, so its state (one 64-bit number) is handed
// from process to process along the pieces in the order of the bytes (for a fluid array: rank 0's planes, then rank
// 1's, ...); each process hashes its own pieces, and nothing but the state is sent. Reading verifies it as for any
// checkpoint: a damaged or truncated file is refused.
//
// Atomic: the processes write "<name>.tmp.<pid of rank 0>"; rank 0 renames it over the checkpoint once every
// process has written and closed it, so a reader sees the previous checkpoint or the complete new one.
// Construction and every call are collective over the communicator. No global state.
// Verified by: the tests RunMpi.* (tests/test_run_mpi.cpp: written on 2 processes, read back and continued on 3
// and in one process; two runs give bitwise the same entries and checksum).
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "immerse/parallel/Communicator.hpp"

namespace immerse::io {

class ParallelCheckpoint {
 public:
  /// Values of an array from `offset` on.
  struct Piece {
    std::size_t offset = 0;
    std::vector<double> values;
  };

  explicit ParallelCheckpoint(Communicator comm) : comm_(comm) {}

  /// `shape` as in Checkpoint::put_array (its product is the array's size); `pieces` this process's values.
  void put_array(const std::string& name, std::vector<std::size_t> shape, std::vector<Piece> pieces);
  void put_int(const std::string& name, std::int64_t value);
  void put_double(const std::string& name, double value);
  void put_string(const std::string& name, std::string value);
  /// String attributes on the file's root (the run's provenance), the same on every process.
  void set_attributes(std::vector<std::pair<std::string, std::string>> attributes) {
    attributes_ = std::move(attributes);
  }

  /// The checksum Checkpoint::checksum() gives for the whole content, on every process. std::logic_error if the
  /// pieces of an array do not tile it.
  std::uint64_t checksum() const;
  /// Writes the checkpoint to `path` atomically; WriteError "cannot write PATH: ..." on every process if any failed.
  void write(const std::filesystem::path& path) const;

 private:
  struct Array {
    std::vector<std::size_t> shape;
    std::size_t size = 0;
    std::vector<Piece> pieces;  ///< ascending offsets
  };
  void check_new_name(const std::string& name) const;

  Communicator comm_;
  std::map<std::string, Array> arrays_;
  std::map<std::string, std::int64_t> ints_;
  std::map<std::string, double> doubles_;
  std::map<std::string, std::string> strings_;
  std::vector<std::pair<std::string, std::string>> attributes_;
};

}  // namespace immerse::io
