#pragma once
/// Data exchanged with the VTK writers and readers besides the meshes.
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include <icd/mesh/core/types.hpp>

namespace icd {

/// A named per-point array: values is #points x k (k components, k >= 1),
/// e.g. "displacement" (#V x 3, metres) or "level" (#V x 1).
struct PointDataArray {
  std::string name;
  Eigen::MatrixXd values;
};

/// How the VTU writers store arrays: "ascii" text, or raw binary in one
/// appended block (format="appended", encoding="raw", UInt64 byte-count
/// headers, little-endian; about 3x smaller and much faster to write and read,
/// read by ParaView, VTK and meshio).
enum class VtuEncoding { Ascii, Binary };

/// Options of the VTU writers.
struct VtuOptions {
  VtuEncoding encoding = VtuEncoding::Ascii;
  /// Per-cell arrays (#cells rows each, >= 1 column), written as CellData.
  std::vector<PointDataArray> cell_data;
  /// Simulated time (s) of the data, written as the field array "TimeValue"
  /// that VTK's readers use as the time of a file series; NaN: none.
  double time = std::numeric_limits<double>::quiet_NaN();
};

/// A set of spheres: centres (#S x 3, model units) and radii (#S, >= 0).
struct SphereSet {
  MatX3d centers;
  Eigen::VectorXd radii;
};

/// One time step of a ParaView PVD collection: simulated time (seconds) and
/// the data file, written as given (normally relative to the .pvd file).
/// Entries of one time with different `part` numbers are the parts of one
/// step (ParaView shows them as the blocks of a multiblock data set).
struct PvdEntry {
  double time = 0.0;
  std::string file;
  int part = 0;  ///< >= 0
};

}  // namespace icd
