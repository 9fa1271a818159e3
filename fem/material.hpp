#pragma once
/// Material parameters of the explicit FEM model (paper section 3, after
/// O'Brien & Hodgins): constitutive model, Young's modulus, Poisson ratio, density.
#include <string>

namespace icd::fem {

/// Constitutive model of an object.
enum class MaterialModel {
  Linear,           ///< small-strain linear elasticity (not rotation invariant)
  Corotational,     ///< linear elasticity in the polar-rotated frame F = R S
  StVK,             ///< St. Venant-Kirchhoff on the Green strain (the paper's model)
  StableNeoHookean  ///< inversion-safe stable Neo-Hookean (Smith et al. 2018, Kim-Eberle form)
};

/// Human-readable name of a model ("linear", "corotational", "stvk", "stable_neo_hookean").
const char* to_string(MaterialModel model);

/// Isotropic elastic material. SI units.
struct Material {
  MaterialModel model = MaterialModel::StVK;
  double young = 1e6;     ///< Young's modulus E in Pa, > 0
  double poisson = 0.3;   ///< Poisson ratio nu in (-1, 0.5)
  double density = 1000;  ///< mass density rho in kg/m^3, > 0
};

/// Lame parameters of a material, in Pa.
struct Lame {
  double mu = 0;      ///< shear modulus E / (2 (1 + nu))
  double lambda = 0;  ///< E nu / ((1 + nu)(1 - 2 nu))
};

/// Throws icd::ParameterError naming the field and the accepted range when
/// E <= 0, nu outside (-1, 0.5), density <= 0, or any value is not finite.
void validate(const Material& material);

/// Lame parameters of a validated material (calls validate()).
Lame lame_parameters(const Material& material);

/// Speed of dilatational waves sqrt((lambda + 2 mu) / rho) in m/s.
double dilatational_wave_speed(const Material& material);

}  // namespace icd::fem
