#pragma once
// Shared scenes of the collision experiments: real meshes (bunny, dragon),
// their octree sphere trees, a coarse node set, and a smooth deformation.
#include <string>

#include <icd/collision/sphere_tree.hpp>
#include <icd/mesh/core/types.hpp>

#include "experiments/common/timing.hpp"

namespace icd::collision::experiments {

/// One deformable object: dense surface, coarse nodes (a vertex subsample
/// standing in for the FEM mesh), an octree tree associated with the nodes.
struct Object {
  std::string name;
  SurfaceMesh dense;
  MatX3d coarse_rest;
  SphereTree tree;
};

/// Reads `file` from the data dir (ICD_DATA_DIR env or the configured one),
/// scales it so its longest bounding-box side is 2 and centres it at `center`,
/// builds an octree tree with `levels` levels and associates ~`coarse_nodes`
/// coarse nodes (every k-th vertex). Throws InputError if the file is missing.
Object load_object(const std::string& file, const Eigen::Vector3d& center, int levels,
                   int coarse_nodes = 800);

/// A deep-tree object from an icosphere (for long traversals).
Object icosphere_object(int subdivisions, double radius, const Eigen::Vector3d& center, int levels);

/// Smooth time-dependent deformation of points (rest positions X, time t):
/// x = X + amplitude * (sin(3 y + t), sin(2 z + 1.3 t), sin(2.5 x + 0.7 t)).
MatX3d deform(const MatX3d& X, double amplitude, double t);

/// Path of a file of the data dir.
std::string data_path(const std::string& file);

using icd::experiments::median;
using icd::experiments::quantile;

}  // namespace icd::collision::experiments
