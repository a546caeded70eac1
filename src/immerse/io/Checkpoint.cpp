#include "immerse/io/Checkpoint.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <numeric>
#include <stdexcept>

#include "immerse/core/Error.hpp"
#include "immerse/io/AtomicFile.hpp"
#include "immerse/io/Fnv1a64.hpp"
#include "immerse/io/Hdf5.hpp"

namespace immerse::io {

namespace {

constexpr const char* kVersionAttr = "immerse_checkpoint_format";
constexpr const char* kChecksumAttr = "checksum_fnv1a64";

}  // namespace

void Checkpoint::check_new_name(const std::string& name) const {
  if (name.empty() || name == "." || name.find('/') != std::string::npos)
    throw std::logic_error("checkpoint: bad entry name '" + name + "'");
  if (has(name)) throw std::logic_error("checkpoint: entry '" + name + "' is already set");
}

void Checkpoint::put_array(const std::string& name, std::vector<double> values, std::vector<std::size_t> shape) {
  check_new_name(name);
  if (shape.empty()) shape = {values.size()};
  if (std::accumulate(shape.begin(), shape.end(), std::size_t{1}, std::multiplies<>()) != values.size())
    throw std::logic_error("checkpoint: shape of '" + name + "' does not match its size");
  arrays_[name] = {std::move(values), std::move(shape)};
}
void Checkpoint::put_int(const std::string& name, std::int64_t value) {
  check_new_name(name);
  ints_[name] = value;
}
void Checkpoint::put_double(const std::string& name, double value) {
  check_new_name(name);
  doubles_[name] = value;
}
void Checkpoint::put_string(const std::string& name, std::string value) {
  check_new_name(name);
  strings_[name] = std::move(value);
}

void Checkpoint::erase(const std::string& name) {
  arrays_.erase(name);
  ints_.erase(name);
  doubles_.erase(name);
  strings_.erase(name);
}

void Checkpoint::invalid(const std::string& name, const std::string& what) const {
  throw InputError("checkpoint " + source_ + ": " + name + " " + what);
}

bool Checkpoint::has(const std::string& name) const {
  return arrays_.contains(name) || ints_.contains(name) || doubles_.contains(name) || strings_.contains(name);
}

void Checkpoint::missing(const std::string& kind, const std::string& name) const {
  throw InputError("checkpoint " + source_ + ": no " + kind + " named " + name);
}

const std::vector<double>& Checkpoint::array(const std::string& name) const {
  const auto it = arrays_.find(name);
  if (it == arrays_.end()) missing("array", name);
  return it->second.values;
}
const std::vector<std::size_t>& Checkpoint::shape(const std::string& name) const {
  const auto it = arrays_.find(name);
  if (it == arrays_.end()) missing("array", name);
  return it->second.shape;
}
std::int64_t Checkpoint::get_int(const std::string& name) const {
  const auto it = ints_.find(name);
  if (it == ints_.end()) missing("integer", name);
  return it->second;
}
double Checkpoint::get_double(const std::string& name) const {
  const auto it = doubles_.find(name);
  if (it == doubles_.end()) missing("double", name);
  return it->second;
}
const std::string& Checkpoint::get_string(const std::string& name) const {
  const auto it = strings_.find(name);
  if (it == strings_.end()) missing("string", name);
  return it->second;
}

std::uint64_t Checkpoint::checksum() const {
  Fnv1a64 h;
  for (const auto& [name, a] : arrays_) {
    h.text("array:" + name);
    h.u64(a.shape.size());
    for (const auto d : a.shape) h.u64(d);
    h.u64(a.values.size());
    h.bytes(a.values.data(), a.values.size() * sizeof(double));
  }
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
  return h.value();
}

bool Checkpoint::operator==(const Checkpoint& o) const {
  const auto same_bits = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  if (arrays_.size() != o.arrays_.size() || ints_ != o.ints_ || strings_ != o.strings_ ||
      doubles_.size() != o.doubles_.size())
    return false;
  for (const auto& [name, a] : arrays_) {
    const auto it = o.arrays_.find(name);
    if (it == o.arrays_.end() || it->second.shape != a.shape || it->second.values.size() != a.values.size() ||
        (!a.values.empty() &&
         std::memcmp(a.values.data(), it->second.values.data(), a.values.size() * sizeof(double)) != 0))
      return false;
  }
  for (const auto& [name, v] : doubles_) {
    const auto it = o.doubles_.find(name);
    if (it == o.doubles_.end() || !same_bits(v, it->second)) return false;
  }
  return true;
}

void Checkpoint::write(const std::filesystem::path& path) const {
  // Built in memory, then written atomically in one piece (see hdf5::create_memory_file).
  const auto check = [&](bool ok, const std::string& what) {
    if (!ok) throw WriteError("cannot write " + path.string() + ": HDF5 error writing " + what);
  };
  hdf5::Quiet quiet;
  hdf5::Handle file = hdf5::create_memory_file(path.string());
  check(file.valid(), "the file");
  const hid_t root = file.get();
  check(hdf5::write_attribute(root, kVersionAttr, kFormatVersion), "format version");
  check(hdf5::write_attribute(root, kChecksumAttr, checksum()), "checksum");
  for (const auto& [name, value] : attributes_) check(hdf5::write_attribute(root, name, value), name);
  hdf5::Handle arrays = hdf5::create_group(root, "arrays");
  hdf5::Handle ints = hdf5::create_group(root, "int64");
  hdf5::Handle doubles = hdf5::create_group(root, "double");
  hdf5::Handle strings = hdf5::create_group(root, "string");
  check(arrays.valid() && ints.valid() && doubles.valid() && strings.valid(), "groups");
  for (const auto& [name, a] : arrays_) {
    check(hdf5::write_doubles(arrays.get(), name, a.values.data(), {a.values.size()}), "arrays/" + name);
    hdf5::Handle set(H5Dopen2(arrays.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
    check(hdf5::write_attribute(set.get(), "shape", std::vector<std::int64_t>(a.shape.begin(), a.shape.end())),
          "arrays/" + name + " shape");
  }
  for (const auto& [name, v] : ints_) check(hdf5::write_int64(ints.get(), name, &v, {}), "int64/" + name);
  for (const auto& [name, v] : doubles_) check(hdf5::write_doubles(doubles.get(), name, &v, {}), "double/" + name);
  for (const auto& [name, v] : strings_) check(hdf5::write_string(strings.get(), name, v), "string/" + name);
  check(arrays.close() && ints.close() && doubles.close() && strings.close(), "groups");
  std::string image;
  check(hdf5::file_image(file.get(), image), "the file image");
  check(file.close(), "the file image");
  AtomicFile::write(path, image);
}

Checkpoint Checkpoint::read(const std::filesystem::path& path) {
  const std::string who = "checkpoint " + path.string();
  {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw InputError(who + ": cannot read: " + std::strerror(errno));
    ::close(fd);
  }
  hdf5::Quiet quiet;
  if (H5Fis_hdf5(path.c_str()) <= 0) throw InputError(who + " is truncated or not an HDF5 file");
  hdf5::Handle file = hdf5::open_file_readonly(path);
  if (!file.valid()) throw InputError(who + " is truncated or not an HDF5 file");
  const hid_t root = file.get();
  const auto corrupted = [&](const std::string& what) { return InputError(who + " is corrupted: " + what); };
  const htri_t has_version = H5Aexists(root, kVersionAttr);
  if (has_version == 0) throw InputError(who + " is not an immerse checkpoint (no format version)");
  std::int64_t version = 0;
  if (has_version < 0 || !hdf5::read_attribute(root, kVersionAttr, version))
    throw corrupted("cannot read the format version");
  if (version != kFormatVersion)
    throw InputError(who + " was written by format version " + std::to_string(version) +
                     ", this program reads version " + std::to_string(kFormatVersion));
  std::uint64_t stored = 0;
  if (!hdf5::read_attribute(root, kChecksumAttr, stored)) throw corrupted("cannot read the checksum");

  Checkpoint c;
  c.source_ = path.string();
  std::vector<std::string> names;
  std::vector<hsize_t> dims;
  const auto group = [&](const char* g) {
    hdf5::Handle h = hdf5::open_group(root, g);
    if (!h.valid() || !hdf5::list_names(h.get(), names)) throw corrupted(std::string("cannot read group ") + g);
    return h;
  };
  const auto need = [&](bool ok, const std::string& what) {
    if (!ok) throw corrupted("cannot read " + what);
  };
  {
    hdf5::Handle g = group("arrays");
    for (const auto& name : names) {
      Array a;
      need(hdf5::read_doubles(g.get(), name, a.values, dims) && dims.size() == 1, "arrays/" + name);
      hdf5::Handle set(H5Dopen2(g.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
      std::vector<std::int64_t> shape;
      need(set.valid() && hdf5::read_attribute(set.get(), "shape", shape), "arrays/" + name + " shape");
      a.shape.assign(shape.begin(), shape.end());
      c.arrays_[name] = std::move(a);
    }
  }
  {
    hdf5::Handle g = group("int64");
    std::vector<std::int64_t> v;
    for (const auto& name : names) {
      need(hdf5::read_int64(g.get(), name, v, dims) && v.size() == 1, "int64/" + name);
      c.ints_[name] = v[0];
    }
  }
  {
    hdf5::Handle g = group("double");
    std::vector<double> v;
    for (const auto& name : names) {
      need(hdf5::read_doubles(g.get(), name, v, dims) && v.size() == 1, "double/" + name);
      c.doubles_[name] = v[0];
    }
  }
  {
    hdf5::Handle g = group("string");
    for (const auto& name : names) need(hdf5::read_string(g.get(), name, c.strings_[name]), "string/" + name);
  }
  if (c.checksum() != stored) throw corrupted("checksum mismatch");
  return c;
}

}  // namespace immerse::io
