// The sphere-fit presets of the preprocessing (icd-preprocess --sphere-fit,
// scene field preprocess.tree_fit): names, and what each sets and keeps.
#include <gtest/gtest.h>

#include <string>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/pipeline/preprocess.hpp>

namespace icd::mesh {
namespace {

TEST(SphereFit, NamesRoundTripAndABadNameNamesTheField) {
  for (SphereFit fit : {SphereFit::light, SphereFit::full, SphereFit::shell})
    EXPECT_EQ(parse_sphere_fit(to_string(fit)), fit);
  try {
    parse_sphere_fit("tight", "--sphere-fit");
    FAIL() << "an unknown fit must be refused";
  } catch (const ParameterError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("--sphere-fit"), std::string::npos) << what;
    EXPECT_NE(what.find("'tight'"), std::string::npos) << what;
  }
}

TEST(SphereFit, KeepsTheTreeShapeAndSetsTheFit) {
  SphereTreeOptions shaped;
  shaped.depth = 2;
  shaped.branching = 4;
  shaped.max_spheres_per_level = {1, 4, 9};
  shaped.threads = 1;
  shaped.time_limit = 5;
  shaped.reduction.lloyd_iterations = 3;  // a fitting option: each preset sets its own
  const SphereTreeOptions builder;
  for (SphereFit fit : {SphereFit::light, SphereFit::full, SphereFit::shell}) {
    SCOPED_TRACE(to_string(fit));
    SphereTreeOptions o = shaped;
    apply_sphere_fit(fit, o);
    EXPECT_EQ(o.depth, 2);
    EXPECT_EQ(o.branching, 4);
    EXPECT_EQ(o.max_spheres_per_level, shaped.max_spheres_per_level);
    EXPECT_EQ(o.threads, 1);
    EXPECT_EQ(o.time_limit, 5);
    const bool light = fit == SphereFit::light, shell = fit == SphereFit::shell;
    EXPECT_EQ(o.reduction.lloyd_iterations, light ? 1 : builder.reduction.lloyd_iterations);
    EXPECT_EQ(o.sampling.refinement_iterations, light ? 0 : builder.sampling.refinement_iterations);
    EXPECT_EQ(o.reduction.joint_leaf_refinement, shell);
    EXPECT_EQ(o.allocation.regroup_parents, shell);
    EXPECT_EQ(o.allocation.worst_share, shell ? 1.0 : builder.allocation.worst_share);
    EXPECT_EQ(o.allocation.leaf_worst_target, shell ? 0.0 : builder.allocation.leaf_worst_target);
  }
  // The preprocessing's default is the light fit with no time limit.
  const PreprocessOptions p;
  SphereTreeOptions light = p.spheres;
  apply_sphere_fit(SphereFit::light, light);
  EXPECT_EQ(light.reduction.lloyd_iterations, p.spheres.reduction.lloyd_iterations);
  EXPECT_EQ(light.sampling.medial_spacing, p.spheres.sampling.medial_spacing);
  EXPECT_EQ(light.sampling.cover_spacing, p.spheres.sampling.cover_spacing);
  EXPECT_GE(p.spheres.time_limit, 1e9);
}

}  // namespace
}  // namespace icd::mesh
