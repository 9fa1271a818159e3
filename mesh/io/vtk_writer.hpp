#pragma once
/// Writing meshes, sphere sets and time series for ParaView and meshio:
/// VTK XML UnstructuredGrid (.vtu), ASCII (doubles in the shortest form that
/// reads back exactly) or raw appended binary (VtuOptions), and PVD
/// collections. Every file is written atomically (see write_file_atomically).
///
/// Common errors: ParameterError (message names the file and the array/row)
/// for non-finite coordinates or values, indices outside [0, #points), a point
/// data array whose row count differs from #points (a cell-data array: #cells)
/// or that has no columns, an empty or duplicate array name, a negative PVD part; InputError if the file cannot be written.
#include <filesystem>
#include <span>

#include <icd/mesh/core/types.hpp>
#include <icd/mesh/io/vtk_types.hpp>

namespace icd {

/// Writes the tetrahedra T of `mesh` as VTK_TETRA (10) cells over the points V,
/// plus the optional point-data arrays (#V rows each). The boundary F is not
/// written (read_vtu_tet_mesh recomputes it).
void write_vtu_tet_mesh(const std::filesystem::path& path, const TetMesh& mesh,
                        std::span<const PointDataArray> point_data = {},
                        const VtuOptions& options = {});

/// Writes the triangles F of `mesh` as VTK_TRIANGLE (5) cells over the points V.
void write_vtu_surface_mesh(const std::filesystem::path& path, const SurfaceMesh& mesh,
                            std::span<const PointDataArray> point_data = {},
                        const VtuOptions& options = {});

/// Writes one VTK_VERTEX (1) cell per sphere centre and the radii as the
/// point-data array "radius" (so ParaView's Glyph filter can scale spheres by
/// it), plus the optional arrays (#S rows each; none may be named "radius").
/// Radii must be finite and >= 0. An empty set (no spheres) is a valid,
/// readable file: no points and one VTK_POLY_VERTEX (2) cell of no points,
/// always ASCII (meshio 5 misreads empty arrays in appended binary).
/// Cell data (VtuOptions) has one row per sphere (one row if empty).
void write_vtu_sphere_set(const std::filesystem::path& path, const SphereSet& spheres,
                          std::span<const PointDataArray> point_data = {},
                        const VtuOptions& options = {});

/// Writes a PVD collection listing `entries` in the given order (one
/// DataSet per entry, with its part number). Times must be finite; file
/// names non-empty; parts >= 0.
void write_pvd(const std::filesystem::path& path, std::span<const PvdEntry> entries);

}  // namespace icd
