#pragma once
/// Everything the simulation needs of one object, CGAL-free: the dense
/// surface, the coarse tet mesh, the rigid links and the sphere tree tied to
/// the coarse nodes. Built from a generated primitive, or loaded from an asset
/// bundle (preprocessing a raw mesh into the cache on first use).
#include <filesystem>

#include <icd/coupling/asset_bundle.hpp>
#include <icd/mesh/core/types.hpp>
#include "experiments/runner/child_process.hpp"
#include "experiments/runner/scene.hpp"

namespace icd::runner {

/// One object's data, in the scene's units (metres) once placed: the same
/// structure the asset bundles hold (dense surface, coarse mesh, reduced
/// coordinates Q, rigid links, sphere tree with its node association).
using ObjectAsset = coupling::AssetBundle;

/// Loads the asset of an object spec: generated primitive, bundle folder, or
/// raw mesh preprocessed into `cache_dir` by the icd-preprocess tool found in
/// `tool_dir` (so the runtime never links CGAL). The tool runs without a
/// shell (the paths are plain arguments) under `limits`. Throws InputError
/// naming the object and the file on failure.
ObjectAsset load_object_asset(const ObjectSpec& spec, const std::filesystem::path& cache_dir,
                              const std::filesystem::path& tool_dir,
                              const ChildLimits& limits = {});

/// Checks, without loading anything, that the object's input files exist, are
/// regular files within their size limits (icd::file_limits) and, for a raw
/// mesh, have a known extension. Throws InputError "object \"<name>\":
/// <path>: <what>". Nothing to check for a primitive.
void check_object_inputs(const ObjectSpec& spec);

/// Scales (longest bounding-box side of the dense mesh -> spec.size, when > 0),
/// rotates (XYZ Euler, degrees) about the dense bounding-box centre and moves
/// that centre to spec.position: dense, coarse, spheres and association rest
/// distances alike.
void place_object(ObjectAsset& asset, const ObjectSpec& spec);

}  // namespace icd::runner
