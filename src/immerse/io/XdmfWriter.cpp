#include "immerse/io/XdmfWriter.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "immerse/core/Error.hpp"
#include "immerse/io/AtomicFile.hpp"
#include "immerse/io/CellFields.hpp"
#include "immerse/io/Hdf5.hpp"
#include "immerse/io/TomlFormat.hpp"
#include "immerse/walls/WallGeometry.hpp"

namespace immerse::io {

namespace {

void check_name(const std::string& what, const std::string& name) {
  bool ok = !name.empty();
  for (const char c : name) ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.');
  if (!ok) throw std::logic_error("XdmfWriter: bad " + what + " name '" + name + "'");
}

std::string dims_text(const std::vector<hsize_t>& dims) {
  std::string s;
  for (const auto d : dims) s.append(s.empty() ? "" : " ").append(std::to_string(d));
  return s;
}

std::string data_item(const std::string& file, const std::string& dataset, const std::vector<hsize_t>& dims,
                      bool integer) {
  return "<DataItem Dimensions=\"" + dims_text(dims) + "\" NumberType=\"" + (integer ? "Int" : "Float") +
         "\" Precision=\"" + (integer ? "4" : "8") + "\" Format=\"HDF\">" + file + ":" + dataset + "</DataItem>";
}

std::string attribute(const std::string& name, const char* type, const char* center, const std::string& item) {
  return "      <Attribute Name=\"" + name + "\" AttributeType=\"" + type + "\" Center=\"" + center + "\">\n        " +
         item + "\n      </Attribute>\n";
}

std::vector<double> flatten(std::span<const Vec3> v) {
  std::vector<double> out;
  out.reserve(3 * v.size());
  for (const auto& p : v) out.insert(out.end(), {p.x, p.y, p.z});
  return out;
}

const char* kSeriesTail = "    </Grid>\n  </Domain>\n</Xdmf>\n";
const char* kMembraneAttr = "xdmf_membranes";
const char* kFluidAttr = "xdmf_fluid";

std::string frame_tag(int frame) {
  char tag[16];
  std::snprintf(tag, sizeof tag, "%06d", frame);
  return tag;
}

}  // namespace

std::string XdmfWriter::frame_file_name(int frame) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "fields_%06d.h5", frame);
  return buf;
}

XdmfWriter::XdmfWriter(std::filesystem::path dir, int first_frame) : dir_(std::move(dir)) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw WriteError("cannot write " + dir_.string() + ": " + ec.message());
  if (first_frame == 0) return;
  // A restart: the series files are rebuilt from the fragments stored in frames 0..first_frame-1 (one at a time).
  hdf5::Quiet quiet;
  std::string membranes = series_head("membranes"), fluid = series_head("fluid");
  for (int f = 0; f < first_frame; ++f) {
    const std::filesystem::path p = dir_ / frame_file_name(f);
    hdf5::Handle file = H5Fis_hdf5(p.c_str()) > 0 ? hdf5::open_file_readonly(p) : hdf5::Handle{};
    std::string m, fl;
    if (!file.valid() || !hdf5::read_attribute(file.get(), kMembraneAttr, m) ||
        !hdf5::read_attribute(file.get(), kFluidAttr, fl))
      throw InputError("cannot continue the output series: " + p.string() +
                       " is missing, truncated or not written by immerse");
    membranes += m;
    fluid += fl;
  }
  AtomicFile::write(dir_ / "membranes.xdmf", membranes + kSeriesTail);
  AtomicFile::write(dir_ / "fluid.xdmf", fluid + kSeriesTail);
  frames_ = first_frame;
}

std::filesystem::path XdmfWriter::write_frame(double time, std::span<const SurfaceFrame> membranes,
                                              const FluidFrame* fluid) {
  const int frame = frames();
  const std::string fname = frame_file_name(frame);
  const std::filesystem::path path = dir_ / fname;

  // Built in memory, then written atomically in one piece (see hdf5::create_memory_file).
  const auto check = [&](bool ok, const std::string& what) {
    if (!ok) throw WriteError("cannot write " + path.string() + ": HDF5 error writing " + what);
  };
  hdf5::Quiet quiet;
  hdf5::Handle file = hdf5::create_memory_file(path.string());
  check(file.valid(), "the file");
  check(hdf5::write_attribute(file.get(), "time", time), "time");
  for (const auto& [name, value] : attributes_) check(hdf5::write_attribute(file.get(), name, value), name);

  // Membranes: all surfaces of the frame in one grid (readable by meshio's XDMF time series as well as ParaView),
  // each element tagged with its membrane's index (cell data membrane_id), the names listed in order.
  std::string mx;
  if (!membranes.empty()) {
    hsize_t nn = 0, nt = 0;
    std::string names;
    for (const auto& m : membranes) {
      check_name("membrane", m.name);
      names += (names.empty() ? "" : " ") + m.name;
      nn += m.nodes.size();
      nt += m.triangles.size();
      const auto& first = membranes.front();
      bool same = m.vectors.size() == first.vectors.size() && m.scalars.size() == first.scalars.size();
      for (std::size_t i = 0; same && i < m.vectors.size(); ++i) same = m.vectors[i].first == first.vectors[i].first;
      for (std::size_t i = 0; same && i < m.scalars.size(); ++i) same = m.scalars[i].first == first.scalars[i].first;
      if (!same) throw std::logic_error("XdmfWriter: membrane " + m.name + " has other fields than " + first.name);
    }
    std::vector<double> nodes;
    std::vector<std::int32_t> conn, id;
    std::vector<std::int64_t> node_offsets{0};
    nodes.reserve(3 * nn);
    conn.reserve(6 * nt);
    id.reserve(nt);
    for (std::size_t k = 0; k < membranes.size(); ++k) {
      const auto& m = membranes[k];
      const auto offset = static_cast<std::int32_t>(node_offsets.back());
      for (const auto& tri : m.triangles)
        for (const int v : tri) {
          if (v < 0 || static_cast<std::size_t>(v) >= m.nodes.size())
            throw std::logic_error("XdmfWriter: membrane " + m.name + " has a triangle node outside its nodes");
          conn.push_back(offset + v);
        }
      id.insert(id.end(), m.triangles.size(), static_cast<std::int32_t>(k));
      const auto x = flatten(m.nodes);
      nodes.insert(nodes.end(), x.begin(), x.end());
      node_offsets.push_back(node_offsets.back() + static_cast<std::int64_t>(m.nodes.size()));
    }
    hdf5::Handle g = hdf5::create_group(file.get(), "membranes");
    check(g.valid() && hdf5::write_attribute(g.get(), "names", names), "/membranes");
    check(hdf5::write_doubles(g.get(), "nodes", nodes.data(), {nn, 3}), "/membranes/nodes");
    check(hdf5::write_int32(g.get(), "connectivity", conn.data(), {nt, 6}), "/membranes/connectivity");
    check(hdf5::write_int32(g.get(), "membrane_id", id.data(), {nt}), "/membranes/membrane_id");
    check(hdf5::write_int64(g.get(), "node_offsets", node_offsets.data(), {node_offsets.size()}),
          "/membranes/node_offsets");
    std::vector<std::pair<std::string, std::size_t>> fields;
    const auto field = [&](const std::string& name, auto member, std::size_t width) {
      check_name("field", name);
      std::vector<double> all;
      all.reserve(width * nn);
      for (const auto& m : membranes) {
        const auto& v = member(m);
        if (v.size() != m.nodes.size())
          throw std::logic_error("XdmfWriter: field " + name + " of " + m.name + " has wrong size");
        if constexpr (std::is_same_v<std::decay_t<decltype(v[0])>, Vec3>) {
          const auto x = flatten(v);
          all.insert(all.end(), x.begin(), x.end());
        } else {
          all.insert(all.end(), v.begin(), v.end());
        }
      }
      const std::vector<hsize_t> dims = width == 3 ? std::vector<hsize_t>{nn, 3} : std::vector<hsize_t>{nn};
      check(hdf5::write_doubles(g.get(), name, all.data(), dims), "/membranes/" + name);
      fields.emplace_back(name, width);
    };
    for (std::size_t i = 0; i < membranes.front().vectors.size(); ++i)
      field(membranes.front().vectors[i].first, [i](const SurfaceFrame& m) { return m.vectors[i].second; }, 3);
    for (std::size_t i = 0; i < membranes.front().scalars.size(); ++i)
      field(membranes.front().scalars[i].first, [i](const SurfaceFrame& m) { return m.scalars[i].second; }, 1);
    mx = membranes_fragment(fname, frame, time, names, nn, nt, fields);
    check(g.close(), "/membranes");
  }

  // Fluid: cell-centred fields on a 3DCoRectMesh (XDMF orders dimensions, origin and spacing z, y, x).
  std::string fx;
  if (fluid) {
    const Grid& g = fluid->grid;
    const auto& n = g.n();
    if (fluid->pressure.shape() != n) throw std::logic_error("XdmfWriter: pressure is not cell-centred on the grid");
    for (int d = 0; d < 3; ++d)
      if (fluid->velocity[d].shape() != g.face_shape(d))
        throw std::logic_error("XdmfWriter: velocity does not match the grid's face layout");
    const CellFields cells = CellFields::from_faces(g, fluid->velocity);
    const std::vector<hsize_t> sdims{hsize_t(n[2]), hsize_t(n[1]), hsize_t(n[0])};
    const std::vector<hsize_t> vdims{hsize_t(n[2]), hsize_t(n[1]), hsize_t(n[0]), 3};
    std::vector<double> vel(3 * cells.velocity[0].size());
    for (std::size_t c = 0; c < cells.velocity[0].size(); ++c)
      for (int d = 0; d < 3; ++d) vel[3 * c + d] = cells.velocity[d][c];
    hdf5::Handle fg = hdf5::create_group(file.get(), "fluid");
    check(fg.valid() && hdf5::write_doubles(fg.get(), "velocity", vel.data(), vdims) &&
              hdf5::write_doubles(fg.get(), "pressure", fluid->pressure.data(), sdims) &&
              hdf5::write_doubles(fg.get(), "vorticity_magnitude", cells.vorticity_magnitude.data(), sdims) &&
              fg.close(),
          "/fluid");
    fx = fluid_fragment(fname, frame, time, g);
  }
  check(hdf5::write_attribute(file.get(), kMembraneAttr, mx) && hdf5::write_attribute(file.get(), kFluidAttr, fx),
        "XDMF fragments");
  std::string image;
  check(hdf5::file_image(file.get(), image), "the file image");
  check(file.close(), "the file image");
  AtomicFile::write(path, image);

  append_frame(mx, fx);
  return path;
}

std::string walls_xdmf(const WallGeometry& walls, double h) {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  std::vector<int> shape;
  walls.triangulate(h, v, t, shape);
  std::ostringstream x;
  x.precision(9);
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n  <Domain>\n    <Grid Name=\"walls\" GridType=\"Uniform\">\n"
    << "      <Topology TopologyType=\"Triangle\" NumberOfElements=\"" << t.size() << "\">\n"
    << "        <DataItem Dimensions=\"" << t.size() << " 3\" NumberType=\"Int\" Format=\"XML\">\n";
  for (const auto& tri : t) x << "          " << tri[0] << " " << tri[1] << " " << tri[2] << "\n";
  x << "        </DataItem>\n      </Topology>\n      <Geometry GeometryType=\"XYZ\">\n"
    << "        <DataItem Dimensions=\"" << v.size() << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">\n";
  for (const Vec3& p : v) x << "          " << p.x << " " << p.y << " " << p.z << "\n";
  x << "        </DataItem>\n      </Geometry>\n      <Attribute Name=\"wall\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
    << "        <DataItem Dimensions=\"" << t.size() << "\" NumberType=\"Int\" Format=\"XML\">\n";
  for (const int k : shape) x << "          " << k << "\n";
  x << "        </DataItem>\n      </Attribute>\n    </Grid>\n  </Domain>\n</Xdmf>\n";
  return x.str();
}

std::string XdmfWriter::fluid_fragment(const std::string& file, int frame, double time, const Grid& g) {
  const auto& n = g.n();
  const std::vector<hsize_t> sdims{hsize_t(n[2]), hsize_t(n[1]), hsize_t(n[0])};
  const std::vector<hsize_t> vdims{hsize_t(n[2]), hsize_t(n[1]), hsize_t(n[0]), 3};
  const double h = g.h();
  const Vec3 c0 = g.cell_position(0, 0, 0);
  return "    <Grid Name=\"fluid_" + frame_tag(frame) + "\" GridType=\"Uniform\">\n      <Time Value=\"" +
         format_number(time) + "\"/>\n      <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"" + dims_text(sdims) +
         "\"/>\n      <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n"
         "        <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">" +
         format_number(c0.z) + " " + format_number(c0.y) + " " + format_number(c0.x) +
         "</DataItem>\n        <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">" +
         format_number(h) + " " + format_number(h) + " " + format_number(h) + "</DataItem>\n      </Geometry>\n" +
         attribute("velocity", "Vector", "Node", data_item(file, "/fluid/velocity", vdims, false)) +
         attribute("pressure", "Scalar", "Node", data_item(file, "/fluid/pressure", sdims, false)) +
         attribute("vorticity_magnitude", "Scalar", "Node",
                   data_item(file, "/fluid/vorticity_magnitude", sdims, false)) +
         "    </Grid>\n";
}

std::string XdmfWriter::membranes_fragment(const std::string& file, int frame, double time, const std::string& names,
                                           std::size_t nodes, std::size_t triangles,
                                           const std::vector<std::pair<std::string, std::size_t>>& fields) {
  const hsize_t nn = nodes, nt = triangles;
  std::string mx =
      "    <Grid Name=\"membranes_" + frame_tag(frame) + "\" GridType=\"Uniform\">\n      <Time Value=\"" +
      format_number(time) + "\"/>\n      <Information Name=\"membrane_names\" Value=\"" + names + "\"/>\n"
      "      <Topology TopologyType=\"Triangle_6\" NumberOfElements=\"" + std::to_string(nt) + "\">\n"
      "        " + data_item(file, "/membranes/connectivity", {nt, 6}, true) + "\n      </Topology>\n"
      "      <Geometry GeometryType=\"XYZ\">\n        " + data_item(file, "/membranes/nodes", {nn, 3}, false) +
      "\n      </Geometry>\n" +
      attribute("membrane_id", "Scalar", "Cell", data_item(file, "/membranes/membrane_id", {nt}, true)) +
      // The node positions again as a field: readers of a fixed mesh (meshio) get the moving surface per frame.
      attribute("position", "Vector", "Node", data_item(file, "/membranes/nodes", {nn, 3}, false));
  for (const auto& [name, width] : fields) {
    const std::vector<hsize_t> dims = width == 3 ? std::vector<hsize_t>{nn, 3} : std::vector<hsize_t>{nn};
    mx += attribute(name, width == 3 ? "Vector" : "Scalar", "Node", data_item(file, "/membranes/" + name, dims, false));
  }
  return mx + "    </Grid>\n";
}

void XdmfWriter::append_frame(const std::string& membranes, const std::string& fluid) {
  append_to_series("membranes", membranes);
  append_to_series("fluid", fluid);
  ++frames_;
}

std::string XdmfWriter::series_head(const std::string& name) {
  return "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"3.0\">\n"
         "  <Domain>\n    <Grid Name=\"" + name + "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
}

// The new series file is the old one without its closing tail, then the fragment and the tail, copied through a
// fixed buffer: the writer's memory does not grow with the number of frames.
void XdmfWriter::append_to_series(const std::string& name, const std::string& fragment) const {
  const std::filesystem::path path = dir_ / (name + ".xdmf");
  AtomicFile out(path);
  std::FILE* to = std::fopen(out.temp_path().c_str(), "wb");
  if (!to) out.fail(errno);
  const auto put = [&](const char* data, std::size_t n) {
    if (std::fwrite(data, 1, n, to) != n) {
      const int err = errno;
      std::fclose(to);
      out.fail(err);
    }
  };
  if (frames_ == 0) {
    const std::string head = series_head(name);
    put(head.data(), head.size());
  } else {
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    std::FILE* from = ec ? nullptr : std::fopen(path.c_str(), "rb");
    if (!from || size < std::strlen(kSeriesTail)) {
      if (from) std::fclose(from);
      std::fclose(to);
      out.fail("the series file " + path.string() + " is missing or damaged");
    }
    std::array<char, 65536> buf;
    for (auto left = size - std::strlen(kSeriesTail); left > 0;) {
      const std::size_t n = std::fread(buf.data(), 1, std::min<std::uintmax_t>(left, buf.size()), from);
      if (n == 0) {
        std::fclose(from);
        std::fclose(to);
        out.fail("cannot read the series file " + path.string());
      }
      put(buf.data(), n);
      left -= n;
    }
    std::fclose(from);
  }
  put(fragment.data(), fragment.size());
  put(kSeriesTail, std::strlen(kSeriesTail));
  if (std::fclose(to) != 0) out.fail(errno);
  out.commit();
}

}  // namespace immerse::io
