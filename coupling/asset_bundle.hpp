#pragma once
/// The per-object asset bundle written by icd-preprocess and loaded by the
/// simulator (issue 4): a folder with
///
///   dense_surface.vtu  the dense rest surface (VTK_TRIANGLE cells, ASCII VTU)
///   coarse_tets.vtu    the coarse rest tet mesh (VTK_TETRA cells, ASCII VTU)
///   bundle.icdb        everything else, in the binary format below
///
/// bundle.icdb, all integers and doubles little-endian:
///
///   header (32 bytes):
///     char[8] magic "ICDASSET"
///     u32     format version (kBundleFormatVersion)
///     u32     number of sections S
///     u64     total file size in bytes
///     u64     FNV-1a 64 checksum of the 24 header bytes before it
///   S sections, each a typed array:
///     char[8] name (ASCII, zero padded)
///     u32     element type: 1 = int32, 2 = float64
///     u32     reserved (0)
///     u64     number of elements
///     u64     FNV-1a 64 checksum of the payload bytes
///     payload (elements * 4 or 8 bytes)
///
/// Sections (in this order): "meta" (int32: format counts, see kMeta*),
/// "fprint" (int32 x 8: FNV-1a 64 of the dense V, dense F, coarse V, coarse T
/// arrays as stored in the VTU files, split into low/high 32-bit words),
/// "surfnode" (int32, the coarse surface nodes Q), "lnk_node" (int32 #N x 3),
/// "lnk_alph" (float64 #N x 3), "lnk_coef" (float64 #N x 3), and, for the
/// sphere tree, "sph_cur" / "sph_rest" (float64 #S x 4: x y z r), "sph_fch",
/// "sph_cnt", "sph_lvl" (int32 #S), "sph_loff" (int32 #levels + 1),
/// "asc_off", "asc_node" (int32), "asc_dist" (float64).
///
/// Loading refuses, with an InputError naming the file and what is wrong, a
/// missing file, a file that is not a regular file or above its size limit
/// (icd::file_limits::kBundle, kVtu), a wrong magic or version, a truncated file (header or any
/// section shorter than announced), a checksum mismatch, sections with
/// unexpected names/types/lengths, VTU meshes whose fingerprints differ from
/// the ones recorded (files mixed from different runs), and inconsistent
/// contents (link indices out of range, invalid sphere tree).
#include <cstdint>
#include <filesystem>

#include <Eigen/Core>

#include <icd/collision/sphere_tree.hpp>
#include <icd/coupling/rigid_links.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::coupling {

/// Version of bundle.icdb written by this build; loading accepts exactly it.
inline constexpr uint32_t kBundleFormatVersion = 1;

/// Everything the simulator needs about one deformable object, in its rest state.
struct AssetBundle {
  SurfaceMesh dense;              ///< dense rest surface (V #N x 3, F outward)
  TetMesh coarse;                 ///< coarse rest mesh (positive tets, F outward boundary)
  Eigen::VectorXi surface_nodes;  ///< the reduced coordinates Q: coarse node indices
  RigidLinks links;               ///< one link per dense vertex (Eqs. 1-10)
  /// Sphere tree in rest configuration with its node associations V_i (paper
  /// 4.4); may be empty (num_nodes() == 0) when the bundle has none.
  collision::SphereTree spheres;
};

/// File names inside a bundle folder.
inline constexpr const char* kDenseSurfaceFile = "dense_surface.vtu";
inline constexpr const char* kCoarseTetsFile = "coarse_tets.vtu";
inline constexpr const char* kBundleDataFile = "bundle.icdb";

/// Writes `bundle` into `folder` (created if missing; existing bundle files
/// replaced, each atomically). Same bundle -> byte-identical files.
/// Throws ParameterError when the bundle is inconsistent (sizes, indices),
/// InputError when a file cannot be written.
void write_asset_bundle(const std::filesystem::path& folder, const AssetBundle& bundle);

/// Loads and checks the bundle in `folder` (see the file comment for what is
/// refused). The coarse boundary F is recomputed from T.
AssetBundle read_asset_bundle(const std::filesystem::path& folder);

/// 64-bit FNV-1a hash of `size` bytes (offset basis 14695981039346656037,
/// prime 1099511628211).
uint64_t fnv1a64(const void* data, std::size_t size);

}  // namespace icd::coupling
