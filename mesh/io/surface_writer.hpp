#pragma once
/// Writing triangle surface meshes as OFF or OBJ text (coordinates in the
/// shortest form that reads back to the identical double).
#include <filesystem>

#include <icd/mesh/core/types.hpp>

namespace icd {

/// Writes `mesh` (V #V x 3, F #F x 3) choosing the format by the extension
/// (.off or .obj, case-insensitive), atomically (see write_file_atomically).
/// Throws ParameterError for an unknown extension, non-finite coordinates or
/// indices outside [0, #V); InputError if the file cannot be written.
void write_surface_mesh(const std::filesystem::path& path, const SurfaceMesh& mesh);

/// Writes OFF: "OFF", "#V #F 0", one "x y z" line per vertex, one "3 i j k"
/// line per face (0-based). Same errors as write_surface_mesh.
void write_off(const std::filesystem::path& path, const SurfaceMesh& mesh);

/// Writes OBJ: "v x y z" lines then "f i j k" lines (1-based).
/// Same errors as write_surface_mesh.
void write_obj(const std::filesystem::path& path, const SurfaceMesh& mesh);

}  // namespace icd
