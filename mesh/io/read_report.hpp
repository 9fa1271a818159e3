#pragma once
/// What a mesh reader did besides returning the mesh.
#include <cstdint>
#include <string>
#include <vector>

namespace icd {

/// Filled by the surface readers when a pointer is passed: the detected
/// format, counts, notes on every silent-looking change (triangulation,
/// welding, ignored keywords) and warnings on counts that disagree with the data.
struct ReadReport {
  std::string format;                 ///< e.g. "OFF", "PLY binary_big_endian", "STL ascii"
  int64_t vertices = 0;               ///< rows of the returned V
  int64_t polygons = 0;               ///< faces as stored in the file
  int64_t triangles = 0;              ///< rows of the returned F
  int64_t polygons_triangulated = 0;  ///< polygons with > 3 corners, fan-triangulated
  int64_t corners_welded = 0;         ///< STL: triangle corners merged into shared vertices
  std::vector<std::string> notes;     ///< one human-readable sentence each
  /// Data the file holds beyond what its header announces (ignored, but the
  /// header count is probably wrong): one sentence each. The programs print
  /// them as warnings.
  std::vector<std::string> warnings;
};

}  // namespace icd
