// One side of the A/B of fem code versions (run_ab.sh): compiled twice, once
// against a previous commit's fem sources with the namespace renamed
// (-Dicd=icd_old -DVARIANT=old), once against the working tree
// (-DVARIANT=new), so that both live in one process. The fem_realtime scene:
// StVK, E = 1e6 Pa, nu = 0.3, clamped at x = 0, gravity, Rayleigh alpha = 1,
// the 3,840-tet bar (mesh 0) or block (mesh 1), Simulator defaults but for the
// integrator (0 RK4, 1 symplectic Euler) and the check interval.
#include <vector>

#include "../clamped_bar.hpp"
#include <icd/fem/simulator.hpp>
#include <icd/mesh/core/primitives.hpp>

#define ICD_AB_CAT2(a, b) a##b
#define ICD_AB_CAT(a, b) ICD_AB_CAT2(a, b)
#define ICD_AB_NAME(name) ICD_AB_CAT(name, ICD_AB_CAT(_, VARIANT))

void* ICD_AB_NAME(make_sim)(int integrator, int mesh, int check_interval) {
  using namespace icd;
  using namespace icd::fem;
  BoxMeshOptions bo;
  const bool block = mesh == 1;
  bo.nx = block ? 10 : 40;
  bo.ny = block ? 8 : 4;
  bo.nz = block ? 8 : 4;
  bo.size = block ? Eigen::Vector3d(1.0, 0.8, 0.8) : Eigen::Vector3d(1.0, 0.1, 0.1);
  const TetMesh m = make_box_tet_mesh(bo);
  Model model = clamped_stvk_model(m);
  SimulatorOptions so;
  so.integrator = integrator ? Integrator::SymplecticEuler : Integrator::RK4;
  so.check_interval = check_interval;
  return new Simulator(std::move(model), so);
}

int ICD_AB_NAME(advance)(void* sim) {
  return static_cast<icd::fem::Simulator*>(sim)->advance(1.0 / 60).substeps;
}

double ICD_AB_NAME(lowest_z)(void* sim) {
  return static_cast<icd::fem::Simulator*>(sim)->positions().col(2).minCoeff();
}

void ICD_AB_NAME(free_sim)(void* sim) { delete static_cast<icd::fem::Simulator*>(sim); }
