#pragma once
/// A minimal reader for the VTU files our writers produce (VTK XML
/// UnstructuredGrid, one Piece, "ascii" DataArrays), so that the runtime can
/// load asset meshes without VTK. Binary/appended/compressed data are refused
/// with a clear error.
#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

#include <icd/mesh/core/types.hpp>
#include <icd/mesh/io/vtk_types.hpp>

namespace icd {

/// The raw contents of an UnstructuredGrid piece.
struct VtuData {
  MatX3d points;                           ///< #P x 3
  std::vector<int64_t> connectivity;       ///< concatenated cell vertex indices
  std::vector<int64_t> offsets;            ///< #C end offsets into connectivity
  std::vector<uint8_t> types;              ///< #C VTK cell types
  std::vector<PointDataArray> point_data;  ///< #P x k each, in file order
};

/// Reads and validates a VTU file: counts match the Piece attributes, offsets
/// increase strictly and end at connectivity.size(), connectivity indices are
/// in [0, #P), all values are finite, point-data arrays have #P rows.
/// Throws InputError "<path>: [line N: ]<reason>" on any malformed input.
VtuData read_vtu(const std::filesystem::path& path);

/// Same as read_vtu on in-memory file contents (for fuzzing); `source` names
/// the data in error messages.
VtuData parse_vtu(std::string_view bytes, std::string_view source);

/// Reads a tetrahedral mesh: every cell must be VTK_TETRA (10) and positively
/// oriented (signed volume > 0). F is recomputed with boundary_faces().
/// Point data, if any, is ignored. Throws InputError naming the cell otherwise.
TetMesh read_vtu_tet_mesh(const std::filesystem::path& path);

/// Reads a triangle surface mesh: every cell must be VTK_TRIANGLE (5).
SurfaceMesh read_vtu_surface_mesh(const std::filesystem::path& path);

/// Reads a sphere set: every cell must be VTK_VERTEX (1) and a one-component
/// point-data array "radius" with values >= 0 must be present.
SphereSet read_vtu_sphere_set(const std::filesystem::path& path);

}  // namespace icd
