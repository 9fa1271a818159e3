#include <gtest/gtest.h>

#include <random>
#include <sstream>
#include <string>

#include <icd/collision/sph_io.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::collision {
namespace {

// A small wrapped tree built by hand: root, 3 children, grandchildren 2+0+1.
SphereTree small_tree() {
  SphereTree t;
  t.spheres = {{0, 0, 0, 5},   {1, 0, 0, 2},   {-1, 0, 0, 2}, {0, 1, 0, 2},
               {1.5, 0, 0, 1}, {0.5, 0, 0, 1}, {0, 1.5, 0, 1}};
  build_topology(t, {-1, 0, 0, 0, 1, 1, 3});
  return t;
}

TEST(SphereTree, BuildTopologyFromParents) {
  const SphereTree t = small_tree();
  EXPECT_NO_THROW(validate(t));
  EXPECT_EQ(t.num_levels(), 3);
  EXPECT_EQ(t.first_child[0], 1);
  EXPECT_EQ(t.child_count[0], 3);
  EXPECT_EQ(t.first_child[1], 4);
  EXPECT_EQ(t.child_count[1], 2);
  EXPECT_TRUE(t.is_leaf(2));
  EXPECT_EQ(t.first_child[3], 6);
  EXPECT_EQ(t.level_offset, (std::vector<int32_t>{0, 1, 4, 7}));
  EXPECT_EQ(parents(t), (std::vector<int32_t>{-1, 0, 0, 0, 1, 1, 3}));
}

TEST(SphereTree, BuildTopologyRejectsNonBreadthFirst) {
  SphereTree t = small_tree();
  EXPECT_THROW(build_topology(t, {-1, 0, 0, 0, 3, 1, 1}), ParameterError);
  EXPECT_THROW(build_topology(t, {0, 0, 0, 0, 1, 1, 3}), ParameterError);
  EXPECT_THROW(build_topology(t, {-1, 0, 0, 0, 1, 1}), ParameterError);
}

TEST(SphereTree, ValidateNamesTheBadNode) {
  SphereTree t = small_tree();
  t.spheres[5].r = std::numeric_limits<double>::quiet_NaN();
  try {
    validate(t);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("node 5"), std::string::npos) << e.what();
  }
  t = small_tree();
  t.spheres[2].r = -1;
  EXPECT_THROW(validate(t), InputError);
  t = small_tree();
  t.first_child[3] = 5;
  EXPECT_THROW(validate(t), InputError);
  t = small_tree();
  t.level[4] = 1;
  EXPECT_THROW(validate(t), InputError);
  t = small_tree();
  t.assoc_offset = {0, 1, 1, 1, 1, 1, 1, 1};
  t.assoc_nodes = {3};
  t.assoc_rest_dist = {};
  EXPECT_THROW(validate(t), InputError);
  t.assoc_rest_dist = {1.0};
  EXPECT_NO_THROW(validate(t));
}

TEST(SphIo, RoundTripKeepsSpheresAndTopology) {
  const SphereTree t = small_tree();
  std::stringstream ss;
  write_sph(ss, t, 4);
  // Complete 4-ary tree with 3 levels: 1 + 4 + 16 lines after the header.
  std::string header;
  std::getline(ss, header);
  EXPECT_EQ(header, "3 4");
  int lines = 0;
  for (std::string l; std::getline(ss, l);) ++lines;
  EXPECT_EQ(lines, 21);
  ss.clear();
  ss.seekg(0);
  const SphereTree r = read_sph(ss);
  ASSERT_EQ(r.num_nodes(), t.num_nodes());
  EXPECT_EQ(r.first_child, t.first_child);
  EXPECT_EQ(r.child_count, t.child_count);
  EXPECT_EQ(r.level_offset, t.level_offset);
  for (int i = 0; i < t.num_nodes(); ++i) {
    EXPECT_EQ(r.spheres[i].x, t.spheres[i].x);
    EXPECT_EQ(r.spheres[i].r, t.spheres[i].r);
  }
}

TEST(SphIo, ReadsCompleteLayoutAndDropsUnusedNodes) {
  // levels 2, branch 3: root + 3 children, the middle one unused.
  std::stringstream ss("2 3\n0 0 0 4 1\n1 0 0 1 1\n0 0 0 -1 0\n-1 0 0 1.5 1\n");
  const SphereTree t = read_sph(ss);
  ASSERT_EQ(t.num_nodes(), 3);
  EXPECT_EQ(t.child_count[0], 2);
  EXPECT_DOUBLE_EQ(t.spheres[2].x, -1.0);
  EXPECT_DOUBLE_EQ(t.spheres[2].r, 1.5);
}

TEST(SphIo, RandomTreesRoundTrip) {
  std::mt19937 rng(0);
  for (int trial = 0; trial < 20; ++trial) {
    const int branch = 2 + trial % 7;
    SphereTree t;
    std::vector<int32_t> parent{-1};
    t.spheres.push_back({0, 0, 0, 10});
    std::size_t begin = 0;
    for (int level = 1; level < 4; ++level) {
      const std::size_t end = t.spheres.size();
      for (std::size_t p = begin; p < end; ++p) {
        const int kids = static_cast<int>(rng() % (branch + 1));
        for (int c = 0; c < kids; ++c) {
          t.spheres.push_back(
              {std::ldexp(double(rng()), -20), 0.1 * c, -1.0 / (c + 3), 1.0 / level});
          parent.push_back(static_cast<int32_t>(p));
        }
      }
      begin = end;
    }
    build_topology(t, parent);
    std::stringstream ss;
    write_sph(ss, t, branch);
    const SphereTree r = read_sph(ss);
    ASSERT_EQ(r.num_nodes(), t.num_nodes());
    EXPECT_EQ(parents(r), parent);
    for (int i = 0; i < t.num_nodes(); ++i) {
      EXPECT_EQ(r.spheres[i].x, t.spheres[i].x);
      EXPECT_EQ(r.spheres[i].z, t.spheres[i].z);
    }
  }
}

TEST(SphIo, IgnoresTheToolkitsTrailingOptionsAndEvaluation) {
  // makeTreeMedial appends its options and evaluation after the tree.
  const std::string tree = "2 2\n0 0 0 2 1\n-1 0 0 1 1\n1 0 0 1 1\n";
  std::stringstream plain(tree), with_notes(tree +
                                            "\n\nOptions :\n\ttesterLevels\t: 2\n"
                                            "\tbranch\t: 2\n\toptimise\t: OFF\n\n\n"
                                            "Level 0 : 1 spheres, Error 12.5\n");
  const SphereTree a = read_sph(plain), b = read_sph(with_notes);
  ASSERT_EQ(b.num_nodes(), 3);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(a.spheres[i].x, b.spheres[i].x);
    EXPECT_EQ(a.spheres[i].r, b.spheres[i].r);
  }
  // A numeric line after the declared nodes is still one node line too many.
  std::stringstream extra(tree + "\n\n1 1 1 1 1\nOptions :\n");
  EXPECT_THROW(read_sph(extra), InputError);
}

TEST(SphIo, MalformedFilesThrowInputError) {
  // The child of an unused node: 7 lines of a depth-3 binary tree.
  const std::string child_of_unused =
      "3 2\n0 0 0 1 0\n0 0 0 -1 0\n0 0 0 1 0\n0 0 0 1 0\n0 0 0 1 0\n0 0 0 1 0\n0 0 0 1 0\n";
  const char* bad[] = {
      "",                                         // empty
      "two 3\n",                                  // non-numeric header
      "2 3\n0 0 0 1 1\n1 1 1 1 1\n",              // too few lines
      "1 3\n0 0 0 1 1\n0 0 0 1 1\n",              // too many lines
      "1 3\n0 0 nan 1 1\n",                       // NaN
      "1 3\n0 0 0 inf 1\n",                       // infinite radius
      "1 3\n0 0 x 1 1\n",                         // not a number
      "1 2\n0 0 0 -1 0\n",                        // unused root
      "2 2\n0 0 0 1 0\n0 0 0 -1 0\n0 0 0 1 0\n",  // fine: checks next line is valid
      child_of_unused.c_str(),
      "30 64\n0 0 0 1 1\n",  // huge declared size
      "12 64\n0 0 0 1 1\n",  // (64^12-1)/63 lines: over the cap
      "-1 2\n",
      "2 0\n",
  };
  for (const char* text : bad) {
    std::stringstream ss(text);
    if (std::string(text) == "2 2\n0 0 0 1 0\n0 0 0 -1 0\n0 0 0 1 0\n") {
      EXPECT_NO_THROW(read_sph(ss));
      continue;
    }
    EXPECT_THROW(read_sph(ss), InputError) << text;
  }
  EXPECT_THROW(read_sph(std::string("/nonexistent/file.sph")), InputError);
}

}  // namespace
}  // namespace icd::collision
