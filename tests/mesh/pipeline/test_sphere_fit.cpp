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
  shaped.lloyd_iterations = 3;  // a fitting option: each preset sets its own
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
    EXPECT_EQ(o.lloyd_iterations, light ? 1 : builder.lloyd_iterations);
    EXPECT_EQ(o.refinement_iterations, light ? 0 : builder.refinement_iterations);
    EXPECT_EQ(o.joint_leaf_refinement, shell);
    EXPECT_EQ(o.regroup_parents, shell);
    EXPECT_EQ(o.worst_share, shell ? 1.0 : builder.worst_share);
    EXPECT_EQ(o.leaf_worst_target, shell ? 0.0 : builder.leaf_worst_target);
  }
  // The preprocessing's default is the light fit with no time limit.
  const PreprocessOptions p;
  SphereTreeOptions light = p.spheres;
  apply_sphere_fit(SphereFit::light, light);
  EXPECT_EQ(light.lloyd_iterations, p.spheres.lloyd_iterations);
  EXPECT_EQ(light.medial_spacing, p.spheres.medial_spacing);
  EXPECT_EQ(light.cover_spacing, p.spheres.cover_spacing);
  EXPECT_GE(p.spheres.time_limit, 1e9);
}

}  // namespace
}  // namespace icd::mesh
