#pragma once
/// Objects generated in code, and placing an object in the world.
#include <string>

#include <Eigen/Core>

#include <icd/coupling/asset_bundle.hpp>

namespace icd::coupling {

/// A mesh generated in code (no preprocessing needed): dense icosphere or box
/// surface on a structured coarse tet mesh.
struct PrimitiveSpec {
  std::string type = "sphere";            ///< "sphere" or "box"
  double radius = 0.1;                    ///< sphere radius, m
  Eigen::Vector3d extent{0.2, 0.2, 0.2};  ///< box sides, m
  int subdivisions = 3;                   ///< icosphere subdivisions of the dense surface
  int cells = 4;                          ///< coarse cells along the longest side
};

/// Builds a primitive object: a dense icosphere (or box surface) over a
/// structured coarse tet mesh (for a sphere: the cells of a grid inside the
/// ball), octree sphere tree `depth` levels below the root, rigid links and
/// sphere-node association. Throws ParameterError when the grid is too
/// coarse for the ball.
AssetBundle make_primitive_asset(const PrimitiveSpec& spec, int depth);

/// Where and how large an object stands in the world.
struct Placement {
  double size = 0;  ///< scale so the longest bounding-box side is this (m); 0 = keep units
  Eigen::Vector3d position = Eigen::Vector3d::Zero();      ///< of the bounding-box centre, m
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();  ///< XYZ Euler angles, degrees
};

/// The rotation of place_asset(): XYZ Euler angles in degrees, R = Rz Ry Rx.
Eigen::Matrix3d rotation_matrix(const Eigen::Vector3d& rotation_deg);

/// Scales (longest bounding-box side of the dense mesh -> placement.size,
/// when > 0), rotates (XYZ Euler, degrees) about the dense bounding-box
/// centre and moves that centre to placement.position: dense, coarse,
/// spheres, link coefficients and association rest distances alike.
void place_asset(AssetBundle& asset, const Placement& placement);

/// Builds the octree sphere tree of `asset`'s dense surface, `depth` levels
/// below the root, each sphere tied to its nearest coarse surface nodes.
void build_octree_spheres(AssetBundle& asset, int depth);

}  // namespace icd::coupling
