#pragma once
/// Data exchanged with the VTK writers and readers besides the meshes.
#include <string>

#include <Eigen/Core>

#include <icd/mesh/core/types.hpp>

namespace icd {

/// A named per-point array: values is #points x k (k components, k >= 1),
/// e.g. "displacement" (#V x 3, metres) or "level" (#V x 1).
struct PointDataArray {
  std::string name;
  Eigen::MatrixXd values;
};

/// A set of spheres: centres (#S x 3, model units) and radii (#S, >= 0).
struct SphereSet {
  MatX3d centers;
  Eigen::VectorXd radii;
};

/// One time step of a ParaView PVD collection: simulated time (seconds) and
/// the data file, written as given (normally relative to the .pvd file).
struct PvdEntry {
  double time = 0.0;
  std::string file;
};

}  // namespace icd
