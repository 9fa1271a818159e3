#include <icd/fem/mass.hpp>

#include <cmath>
#include <string>
#include <vector>

#include <icd/mesh/core/error.hpp>

namespace icd::fem {
namespace {
void check_density(double density) {
  if (!std::isfinite(density) || density <= 0)
    throw ParameterError("fem mass: density = " + std::to_string(density) +
                         " is invalid: expected a finite density > 0 kg/m^3");
}
}  // namespace

Eigen::VectorXd lumped_mass(const TetMeshData& mesh, double density) {
  check_density(density);
  Eigen::VectorXd m = Eigen::VectorXd::Zero(mesh.num_nodes);
  for (int e = 0; e < mesh.num_tets(); ++e)
    for (int a = 0; a < 4; ++a) m[mesh.tets(e, a)] += density * mesh.rest_volume[e] / 4.0;
  return m;
}

Eigen::SparseMatrix<double> consistent_mass_matrix(const TetMeshData& mesh, double density) {
  check_density(density);
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(static_cast<size_t>(mesh.num_tets()) * 48);
  for (int e = 0; e < mesh.num_tets(); ++e) {
    const double m = density * mesh.rest_volume[e] / 20.0;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int c = 0; c < 3; ++c)
          trip.emplace_back(3 * mesh.tets(e, a) + c, 3 * mesh.tets(e, b) + c, a == b ? 2 * m : m);
  }
  Eigen::SparseMatrix<double> M(3 * mesh.num_nodes, 3 * mesh.num_nodes);
  M.setFromTriplets(trip.begin(), trip.end());
  return M;
}

}  // namespace icd::fem
