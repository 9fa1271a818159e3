#include <icd/fem/material.hpp>

#include <cmath>
#include <sstream>

#include <icd/mesh/core/error.hpp>

namespace icd::fem {

const char* to_string(MaterialModel model) {
  switch (model) {
    case MaterialModel::Linear:
      return "linear";
    case MaterialModel::Corotational:
      return "corotational";
    case MaterialModel::StVK:
      return "stvk";
    case MaterialModel::StableNeoHookean:
      return "stable_neo_hookean";
  }
  return "unknown";
}

void validate(const Material& material) {
  auto fail = [](const char* field, double value, const char* range) {
    std::ostringstream os;
    os << "fem::Material." << field << " = " << value << " is invalid: expected " << range;
    throw ParameterError(os.str());
  };
  if (!std::isfinite(material.young) || material.young <= 0)
    fail("young", material.young, "a finite Young's modulus > 0 Pa");
  if (!std::isfinite(material.poisson) || material.poisson <= -1.0 || material.poisson >= 0.5)
    fail("poisson", material.poisson, "a Poisson ratio in (-1, 0.5)");
  if (!std::isfinite(material.density) || material.density <= 0)
    fail("density", material.density, "a finite density > 0 kg/m^3");
}

Lame lame_parameters(const Material& material) {
  validate(material);
  const double E = material.young, nu = material.poisson;
  return {E / (2.0 * (1.0 + nu)), E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))};
}

double dilatational_wave_speed(const Material& material) {
  const Lame l = lame_parameters(material);
  return std::sqrt((l.lambda + 2.0 * l.mu) / material.density);
}

}  // namespace icd::fem
