#include <icd/fem/material.hpp>

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include <icd/mesh/core/error.hpp>

namespace icd::fem {
namespace {

TEST(Material, RejectsInvalidParametersNamingTheField) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    double young, poisson, density;
    const char* field;
  };
  for (const Case& c : {Case{0.0, 0.3, 1000, "young"}, Case{-1.0, 0.3, 1000, "young"},
                        Case{nan, 0.3, 1000, "young"}, Case{1e6, 0.5, 1000, "poisson"},
                        Case{1e6, -1.0, 1000, "poisson"}, Case{1e6, 0.7, 1000, "poisson"},
                        Case{1e6, nan, 1000, "poisson"}, Case{1e6, 0.3, 0.0, "density"},
                        Case{1e6, 0.3, -5.0, "density"}}) {
    Material m;
    m.young = c.young;
    m.poisson = c.poisson;
    m.density = c.density;
    try {
      validate(m);
      ADD_FAILURE() << "accepted " << c.field;
    } catch (const ParameterError& e) {
      EXPECT_NE(std::string(e.what()).find(c.field), std::string::npos) << e.what();
    }
  }
}

TEST(Material, AcceptsBoundaryNeighbourhood) {
  Material m;
  m.poisson = 0.4999;
  EXPECT_NO_THROW(validate(m));
  m.poisson = -0.999;
  EXPECT_NO_THROW(validate(m));
}

TEST(Material, LameParametersMatchTheirDefinition) {
  Material m;
  m.young = 2e6;
  m.poisson = 0.25;
  const Lame l = lame_parameters(m);
  // Independent relations: E = mu (3 lambda + 2 mu) / (lambda + mu), nu = lambda / (2 (lambda +
  // mu)).
  EXPECT_NEAR(l.mu * (3 * l.lambda + 2 * l.mu) / (l.lambda + l.mu), 2e6, 1e-6);
  EXPECT_NEAR(l.lambda / (2 * (l.lambda + l.mu)), 0.25, 1e-14);
}

}  // namespace
}  // namespace icd::fem
