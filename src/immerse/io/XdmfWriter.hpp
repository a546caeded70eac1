#pragma once
// ParaView output: one HDF5 file per output frame (DIR/fields_000012.h5) and two XDMF 3 files describing the
// whole time series (temporal collections), rewritten atomically after every frame:
//   DIR/membranes.xdmf  all membranes of a frame as one surface of 6-node quadratic triangles (TopologyType
//                       "Triangle_6", node order: vertices 0, 1, 2, then mid-sides 0-1, 1-2, 2-0, as
//                       VTK_QUADRATIC_TRIANGLE) with cell data membrane_id (the membrane's index; names in order in
//                       the grid's Information "membrane_names") and node fields (position, vectors such as force
//                       and velocity, scalars such as tension invariants); meshio.xdmf.TimeSeriesReader reads it;
//   DIR/fluid.xdmf      the fluid on the cell centres of the MAC grid (3DCoRectMesh): cell-centred velocity,
//                       pressure and vorticity magnitude (CellFields).
// HDF5 layout of a frame: attributes "time" and the run's provenance; /membranes/{nodes [N,3], connectivity [T,6]
// int32, membrane_id [T] int32, node_offsets [M+1] int64 (membrane k owns nodes node_offsets[k] ..
// node_offsets[k+1]-1), <field> [N,3] or [N]} with attribute "names" (space-separated, in order);
// /fluid/{velocity [nz,ny,nx,3], pressure [nz,ny,nx], vorticity_magnitude [nz,ny,nx]}.
// Each frame file also stores its own XDMF fragments (attributes), so a restarted run can rebuild the series.
// Each frame appends its fragments to the series files (rewritten atomically through a fixed buffer), so the
// writer's memory does not grow with the number of frames.
#include <array>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "immerse/core/Array3.hpp"
#include "immerse/core/Vec3.hpp"
#include "immerse/grid/FaceField.hpp"
#include "immerse/grid/Grid.hpp"

namespace immerse {
class WallGeometry;
}

namespace immerse::io {

/// One membrane surface at one output time. Names are [A-Za-z0-9_.-]; every field has one value per node; all
/// membranes of a frame have the same fields in the same order.
struct SurfaceFrame {
  std::string name;
  std::span<const Vec3> nodes;
  std::span<const std::array<int, 6>> triangles;
  std::vector<std::pair<std::string, std::span<const Vec3>>> vectors;
  std::vector<std::pair<std::string, std::span<const double>>> scalars;
};

/// The fluid at one output time: face velocities and cell-centred pressure on `grid`.
struct FluidFrame {
  const Grid& grid;
  const FaceField& velocity;
  const Array3& pressure;
};

/// An XDMF file of the walls' surfaces (WallGeometry::triangulate at spacing h), the data inline: a Triangle grid
/// with the cell attribute `wall`, the index of the [[wall]] entry of each triangle.
std::string walls_xdmf(const WallGeometry& walls, double h);

class XdmfWriter {
 public:
  /// Writes into `dir` (created if missing). `first_frame` > 0 continues a restarted run: frames
  /// 0..first_frame-1 already exist in `dir` and are read back into the series (InputError if one is missing
  /// or damaged); later frames are overwritten.
  explicit XdmfWriter(std::filesystem::path dir, int first_frame = 0);

  /// Writes frame number frames() at `time` and updates both XDMF files. Returns the HDF5 file written.
  /// Throws InputError "cannot write <path>: ..." on I/O failure, std::logic_error on inconsistent sizes.
  std::filesystem::path write_frame(double time, std::span<const SurfaceFrame> membranes,
                                    const FluidFrame* fluid = nullptr);

  /// String attributes written on the root of every later frame file (the run's provenance).
  void set_attributes(std::vector<std::pair<std::string, std::string>> attributes) {
    attributes_ = std::move(attributes);
  }

  /// Appends frame number frames(), whose file another writer made (ParallelFrameWriter), to both series.
  void append_frame(const std::string& membranes_fragment, const std::string& fluid_fragment);
  /// The XDMF fragments of frame `frame` in `file`, as write_frame stores and appends them: the membranes (names
  /// space-separated, node and triangle counts, the fields after position with 3 or 1 values per node) and the fluid.
  static std::string membranes_fragment(const std::string& file, int frame, double time, const std::string& names,
                                        std::size_t nodes, std::size_t triangles,
                                        const std::vector<std::pair<std::string, std::size_t>>& fields);
  static std::string fluid_fragment(const std::string& file, int frame, double time, const Grid& grid);
  /// The names of the root attributes holding a frame file's two fragments.
  static constexpr const char* kMembranesAttribute = "xdmf_membranes";
  static constexpr const char* kFluidAttribute = "xdmf_fluid";

  int frames() const { return frames_; }
  const std::filesystem::path& dir() const { return dir_; }
  static std::string frame_file_name(int frame);

 private:
  static std::string series_head(const std::string& name);
  void append_to_series(const std::string& name, const std::string& fragment) const;

  std::filesystem::path dir_;
  int frames_ = 0;
  std::vector<std::pair<std::string, std::string>> attributes_;
};

}  // namespace immerse::io
