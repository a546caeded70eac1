#pragma once
// Thin RAII helpers over the HDF5 C API, shared by the checkpoint and ParaView writers.
// All functions report failure through their return value; callers turn it into a one-line error.
#include <hdf5.h>

#include <cstdint>
#include <string>
#include <vector>

namespace immerse::io::hdf5 {

/// Owns one HDF5 identifier and closes it with the matching H5?close.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Handle(Handle&& o) noexcept : id_(o.id_), closer_(o.closer_) { o.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept;
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { close(); }

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  /// Closes now; false if HDF5 reports an error (e.g. a failed flush of a file).
  bool close();

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer closer_ = nullptr;
};

/// Silences HDF5's automatic error stack printing while alive (we report errors ourselves).
class Quiet {
 public:
  Quiet();
  ~Quiet();
  Quiet(const Quiet&) = delete;
  Quiet& operator=(const Quiet&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

/// Creates a new file in memory only (HDF5's core driver without backing store; `name` identifies it), with
/// checksummed (1.8+) metadata. Its bytes are then taken with file_image and written by the caller (atomically,
/// with the operating system's own error on a full disk: HDF5 never writes to, or fails on, the disk itself).
Handle create_memory_file(const std::string& name);
/// The complete bytes of an open file (flushed first).
bool file_image(hid_t file, std::string& bytes);
Handle open_file_readonly(const std::string& path);
Handle create_group(hid_t loc, const std::string& name);
Handle open_group(hid_t loc, const std::string& name);

/// Writes an n-dimensional dataset of doubles / int32 / int64 (dims slowest first).
bool write_doubles(hid_t loc, const std::string& name, const double* data, const std::vector<hsize_t>& dims);
bool write_int32(hid_t loc, const std::string& name, const std::int32_t* data, const std::vector<hsize_t>& dims);
bool write_int64(hid_t loc, const std::string& name, const std::int64_t* data, const std::vector<hsize_t>& dims);
/// A scalar dataset holding a fixed-length string.
bool write_string(hid_t loc, const std::string& name, const std::string& value);

/// Dimensions of a dataset (empty and false on failure).
bool dataset_dims(hid_t loc, const std::string& name, std::vector<hsize_t>& dims);
bool read_doubles(hid_t loc, const std::string& name, std::vector<double>& out, std::vector<hsize_t>& dims);
bool read_int32(hid_t loc, const std::string& name, std::vector<std::int32_t>& out, std::vector<hsize_t>& dims);
bool read_int64(hid_t loc, const std::string& name, std::vector<std::int64_t>& out, std::vector<hsize_t>& dims);
bool read_string(hid_t loc, const std::string& name, std::string& out);

/// Attributes on an object: a scalar int64 / uint64 / double, a 1D int64 array, or a string.
bool write_attribute(hid_t obj, const std::string& name, std::int64_t value);
bool write_attribute(hid_t obj, const std::string& name, std::uint64_t value);
bool write_attribute(hid_t obj, const std::string& name, double value);
bool write_attribute(hid_t obj, const std::string& name, const std::vector<std::int64_t>& value);
bool write_attribute(hid_t obj, const std::string& name, const std::string& value);
bool read_attribute(hid_t obj, const std::string& name, std::int64_t& value);
bool read_attribute(hid_t obj, const std::string& name, std::uint64_t& value);
bool read_attribute(hid_t obj, const std::string& name, double& value);
bool read_attribute(hid_t obj, const std::string& name, std::vector<std::int64_t>& value);
bool read_attribute(hid_t obj, const std::string& name, std::string& value);

/// Names of the links in a group, in increasing name order.
bool list_names(hid_t group, std::vector<std::string>& names);

}  // namespace immerse::io::hdf5
