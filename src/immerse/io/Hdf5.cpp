#include "immerse/io/Hdf5.hpp"

namespace immerse::io::hdf5 {

Handle& Handle::operator=(Handle&& o) noexcept {
  if (this != &o) {
    close();
    id_ = o.id_;
    closer_ = o.closer_;
    o.id_ = H5I_INVALID_HID;
  }
  return *this;
}

bool Handle::close() {
  if (id_ < 0) return true;
  const herr_t rc = closer_(id_);
  id_ = H5I_INVALID_HID;
  return rc >= 0;
}

Quiet::Quiet() {
  H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

Quiet::~Quiet() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }

Handle create_memory_file(const std::string& name) {
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!fapl.valid() || H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_LATEST) < 0 ||
      H5Pset_fapl_core(fapl.get(), 1 << 20, false) < 0)
    return {};
  return {H5Fcreate(name.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), H5Fclose};
}

namespace {

// Bob Jenkins' lookup3 hash (hashlittle, public domain), which HDF5 uses for its metadata checksums.
std::uint32_t rot(std::uint32_t x, int k) { return (x << k) | (x >> (32 - k)); }

std::uint32_t lookup3(const unsigned char* k, std::size_t length, std::uint32_t initval) {
  std::uint32_t a = 0xdeadbeef + static_cast<std::uint32_t>(length) + initval, b = a, c = a;
  const auto word = [&](int i) {
    return std::uint32_t(k[i]) | std::uint32_t(k[i + 1]) << 8 | std::uint32_t(k[i + 2]) << 16 |
           std::uint32_t(k[i + 3]) << 24;
  };
  while (length > 12) {
    a += word(0), b += word(4), c += word(8);
    a -= c, a ^= rot(c, 4), c += b;
    b -= a, b ^= rot(a, 6), a += c;
    c -= b, c ^= rot(b, 8), b += a;
    a -= c, a ^= rot(c, 16), c += b;
    b -= a, b ^= rot(a, 19), a += c;
    c -= b, c ^= rot(b, 4), b += a;
    length -= 12, k += 12;
  }
  if (length == 0) return c;
  std::uint32_t tail[3] = {0, 0, 0};
  for (std::size_t i = 0; i < length; ++i) tail[i / 4] |= std::uint32_t(k[i]) << (8 * (i % 4));
  a += tail[0], b += tail[1], c += tail[2];
  c ^= b, c -= rot(b, 14);
  a ^= c, a -= rot(c, 11);
  b ^= a, b -= rot(a, 25);
  c ^= b, c -= rot(b, 16);
  a ^= c, a -= rot(c, 4);
  b ^= a, b -= rot(a, 14);
  c ^= b, c -= rot(b, 24);
  return c;
}

}  // namespace

bool file_image(hid_t file, std::string& bytes) {
  if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) return false;
  const ssize_t n = H5Fget_file_image(file, nullptr, 0);
  if (n <= 0) return false;
  bytes.assign(static_cast<std::size_t>(n), '\0');
  if (H5Fget_file_image(file, bytes.data(), bytes.size()) != n) return false;
  // HDF5 1.10 clears the superblock's "open for writing" flags in the image without recomputing the superblock
  // checksum (versions 2 and 3), which makes the image unreadable; recompute it. The superblock: signature (8),
  // version, size of offsets, size of lengths, flags (1 each), four addresses, then the checksum.
  auto* b = reinterpret_cast<unsigned char*>(bytes.data());
  if (bytes.size() >= 12 && b[8] >= 2) {
    const std::size_t at = 12 + 4 * std::size_t(b[9]);
    if (bytes.size() < at + 4) return false;
    const std::uint32_t sum = lookup3(b, at, 0);
    for (int i = 0; i < 4; ++i) b[at + i] = static_cast<unsigned char>(sum >> (8 * i));
  }
  return true;
}

Handle open_file_readonly(const std::string& path) {
  // Strong close: closing the file also closes anything a failed read on a damaged file left open.
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!fapl.valid() || H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG) < 0) return {};
  return {H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get()), H5Fclose};
}

Handle create_group(hid_t loc, const std::string& name) {
  return {H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose};
}

Handle open_group(hid_t loc, const std::string& name) { return {H5Gopen2(loc, name.c_str(), H5P_DEFAULT), H5Gclose}; }

namespace {

bool write_array(hid_t loc, const std::string& name, hid_t file_type, hid_t mem_type, const void* data,
                 const std::vector<hsize_t>& dims) {
  Handle space(dims.empty() ? H5Screate(H5S_SCALAR)
                            : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
               H5Sclose);
  if (!space.valid()) return false;
  Handle set(H5Dcreate2(loc, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
  static const double dummy = 0;  // HDF5 rejects a null buffer even for zero elements
  return set.valid() && H5Dwrite(set.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data ? data : &dummy) >= 0 &&
         set.close();
}

bool extent(hid_t set, std::vector<hsize_t>& dims) {
  Handle space(H5Dget_space(set), H5Sclose);
  if (!space.valid()) return false;
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0) return false;
  dims.assign(static_cast<std::size_t>(rank), 0);
  return H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) >= 0;
}

template <class T>
bool read_array(hid_t loc, const std::string& name, hid_t mem_type, std::vector<T>& out, std::vector<hsize_t>& dims) {
  Handle set(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!set.valid() || !extent(set.get(), dims)) return false;
  hsize_t n = 1;
  for (const hsize_t d : dims) n *= d;
  out.assign(n, T{});
  T dummy{};
  return H5Dread(set.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, n ? out.data() : &dummy) >= 0;
}

Handle string_type(std::size_t size) {
  Handle t(H5Tcopy(H5T_C_S1), H5Tclose);
  // HDF5 strings have at least one byte; an empty string is stored as one NUL (NULLPAD strips it on reading).
  if (!t.valid() || H5Tset_size(t.get(), size ? size : 1) < 0 || H5Tset_strpad(t.get(), H5T_STR_NULLPAD) < 0)
    return {};
  return t;
}

template <class T>
bool write_scalar_attribute(hid_t obj, const std::string& name, hid_t file_type, hid_t mem_type, const T& value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle a(H5Acreate2(obj, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  return a.valid() && H5Awrite(a.get(), mem_type, &value) >= 0;
}

template <class T>
bool read_scalar_attribute(hid_t obj, const std::string& name, hid_t mem_type, T& value) {
  Handle a(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose);
  if (!a.valid()) return false;
  Handle space(H5Aget_space(a.get()), H5Sclose);
  return space.valid() && H5Sget_simple_extent_npoints(space.get()) == 1 && H5Aread(a.get(), mem_type, &value) >= 0;
}

}  // namespace

bool write_doubles(hid_t loc, const std::string& name, const double* data, const std::vector<hsize_t>& dims) {
  return write_array(loc, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, data, dims);
}
bool write_int32(hid_t loc, const std::string& name, const std::int32_t* data, const std::vector<hsize_t>& dims) {
  return write_array(loc, name, H5T_STD_I32LE, H5T_NATIVE_INT32, data, dims);
}
bool write_int64(hid_t loc, const std::string& name, const std::int64_t* data, const std::vector<hsize_t>& dims) {
  return write_array(loc, name, H5T_STD_I64LE, H5T_NATIVE_INT64, data, dims);
}

bool write_string(hid_t loc, const std::string& name, const std::string& value) {
  Handle type = string_type(value.size());
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  return type.valid() && write_array(loc, name, type.get(), type.get(), padded.data(), {});
}

bool dataset_dims(hid_t loc, const std::string& name, std::vector<hsize_t>& dims) {
  Handle set(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
  return set.valid() && extent(set.get(), dims);
}
bool read_doubles(hid_t loc, const std::string& name, std::vector<double>& out, std::vector<hsize_t>& dims) {
  return read_array(loc, name, H5T_NATIVE_DOUBLE, out, dims);
}
bool read_int32(hid_t loc, const std::string& name, std::vector<std::int32_t>& out, std::vector<hsize_t>& dims) {
  return read_array(loc, name, H5T_NATIVE_INT32, out, dims);
}
bool read_int64(hid_t loc, const std::string& name, std::vector<std::int64_t>& out, std::vector<hsize_t>& dims) {
  return read_array(loc, name, H5T_NATIVE_INT64, out, dims);
}

bool read_string(hid_t loc, const std::string& name, std::string& out) {
  Handle set(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!set.valid()) return false;
  Handle type(H5Dget_type(set.get()), H5Tclose);
  if (!type.valid() || H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) != 0) return false;
  out.assign(H5Tget_size(type.get()), '\0');
  if (out.empty() || H5Dread(set.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0) return false;
  while (!out.empty() && out.back() == '\0') out.pop_back();
  return true;
}

bool write_attribute(hid_t obj, const std::string& name, std::int64_t value) {
  return write_scalar_attribute(obj, name, H5T_STD_I64LE, H5T_NATIVE_INT64, value);
}
bool write_attribute(hid_t obj, const std::string& name, std::uint64_t value) {
  return write_scalar_attribute(obj, name, H5T_STD_U64LE, H5T_NATIVE_UINT64, value);
}
bool write_attribute(hid_t obj, const std::string& name, double value) {
  return write_scalar_attribute(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, value);
}
bool write_attribute(hid_t obj, const std::string& name, const std::vector<std::int64_t>& value) {
  const hsize_t n = value.size();
  Handle space(H5Screate_simple(1, &n, nullptr), H5Sclose);
  Handle a(H5Acreate2(obj, name.c_str(), H5T_STD_I64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  const std::int64_t dummy = 0;
  return a.valid() && H5Awrite(a.get(), H5T_NATIVE_INT64, n ? value.data() : &dummy) >= 0;
}
// A variable-length UTF-8 string: h5py and other readers return it as text (a fixed-length one comes back as bytes).
bool write_attribute(hid_t obj, const std::string& name, const std::string& value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  if (!type.valid() || H5Tset_size(type.get(), H5T_VARIABLE) < 0 || H5Tset_cset(type.get(), H5T_CSET_UTF8) < 0)
    return false;
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle a(H5Acreate2(obj, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  const char* text = value.c_str();
  return a.valid() && H5Awrite(a.get(), type.get(), &text) >= 0;
}

bool read_attribute(hid_t obj, const std::string& name, std::int64_t& value) {
  return read_scalar_attribute(obj, name, H5T_NATIVE_INT64, value);
}
bool read_attribute(hid_t obj, const std::string& name, std::uint64_t& value) {
  return read_scalar_attribute(obj, name, H5T_NATIVE_UINT64, value);
}
bool read_attribute(hid_t obj, const std::string& name, double& value) {
  return read_scalar_attribute(obj, name, H5T_NATIVE_DOUBLE, value);
}
bool read_attribute(hid_t obj, const std::string& name, std::vector<std::int64_t>& value) {
  Handle a(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose);
  if (!a.valid()) return false;
  Handle space(H5Aget_space(a.get()), H5Sclose);
  const hssize_t n = space.valid() ? H5Sget_simple_extent_npoints(space.get()) : -1;
  if (n < 0) return false;
  value.assign(static_cast<std::size_t>(n), 0);
  std::int64_t dummy = 0;
  return H5Aread(a.get(), H5T_NATIVE_INT64, n ? value.data() : &dummy) >= 0;
}
bool read_attribute(hid_t obj, const std::string& name, std::string& value) {
  Handle a(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose);
  if (!a.valid()) return false;
  Handle type(H5Aget_type(a.get()), H5Tclose);
  if (!type.valid() || H5Tget_class(type.get()) != H5T_STRING) return false;
  if (H5Tis_variable_str(type.get()) > 0) {
    Handle memtype(H5Tcopy(H5T_C_S1), H5Tclose);
    char* text = nullptr;
    if (!memtype.valid() || H5Tset_size(memtype.get(), H5T_VARIABLE) < 0 ||
        H5Tset_cset(memtype.get(), H5Tget_cset(type.get())) < 0 || H5Aread(a.get(), memtype.get(), &text) < 0)
      return false;
    value = text ? text : "";
    H5free_memory(text);
    return true;
  }
  value.assign(H5Tget_size(type.get()), '\0');  // fixed length (files of earlier versions)
  if (value.empty() || H5Aread(a.get(), type.get(), value.data()) < 0) return false;
  while (!value.empty() && value.back() == '\0') value.pop_back();
  return true;
}

bool list_names(hid_t group, std::vector<std::string>& names) {
  H5G_info_t info;
  if (H5Gget_info(group, &info) < 0) return false;
  names.clear();
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    const ssize_t len = H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i, nullptr, 0, H5P_DEFAULT);
    if (len < 0) return false;
    std::string name(static_cast<std::size_t>(len) + 1, '\0');
    if (H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i, name.data(), name.size(), H5P_DEFAULT) < 0)
      return false;
    name.pop_back();
    names.push_back(std::move(name));
  }
  return true;
}

}  // namespace immerse::io::hdf5
