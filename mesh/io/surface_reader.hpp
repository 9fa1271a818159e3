#pragma once
/// Reading triangle surface meshes from OFF, OBJ, PLY and STL files, with our
/// own CGAL-free parsers: every failure is an InputError whose message starts
/// with the file path and, where meaningful, the line number or element index;
/// no header count is trusted before it is checked against the file size.
#include <filesystem>
#include <string_view>

#include <icd/mesh/io/read_report.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd {

/// Reads a triangle surface mesh, choosing the parser by the file extension
/// (case-insensitive): .off, .obj, .ply (ascii, binary_little_endian,
/// binary_big_endian), .stl (ascii or binary; identical corners are welded).
/// Polygons with more than 3 corners are fan-triangulated (noted in `report`).
/// Postconditions: V.rows() >= 1, F.rows() >= 1, all coordinates finite, all
/// indices in [0, V.rows()). Unreferenced or duplicate vertices are kept.
/// Throws InputError ("<path>: [line N: ]<reason>") for a missing file, an
/// unknown extension, truncated data, non-numeric tokens, NaN/Inf coordinates,
/// out-of-range (or negative) indices, faces with fewer than 3 corners, header
/// counts that cannot fit in the file, and empty meshes.
SurfaceMesh read_surface_mesh(const std::filesystem::path& path, ReadReport* report = nullptr);

/// Parsers of in-memory file contents, for the reader above and for fuzzing.
/// `source` names the data in error messages (normally the path).
/// Same postconditions and errors as read_surface_mesh.
SurfaceMesh parse_off(std::string_view bytes, std::string_view source,
                      ReadReport* report = nullptr);
/// OBJ: `v` and `f` lines (f corners as i, i/t, i/t/n or i//n; negative
/// indices count back from the last vertex read); other keywords are ignored.
SurfaceMesh parse_obj(std::string_view bytes, std::string_view source,
                      ReadReport* report = nullptr);
/// PLY: element `vertex` with numeric properties x, y, z and element `face`
/// with a list property `vertex_indices` or `vertex_index`; other properties
/// and elements are skipped.
SurfaceMesh parse_ply(std::string_view bytes, std::string_view source,
                      ReadReport* report = nullptr);
/// STL, ASCII or binary (binary when the size is 84 + 50 * count). Corners with
/// bit-identical coordinates (+0 and -0 alike) become one vertex.
SurfaceMesh parse_stl(std::string_view bytes, std::string_view source,
                      ReadReport* report = nullptr);

}  // namespace icd
