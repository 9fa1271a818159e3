#pragma once
/// Reading and writing the `.sph` text format of the sphere-tree toolkits
/// (Bradshaw & O'Sullivan): line 1 `levels branch`, then (B^L - 1)/(B - 1)
/// lines `x y z r occupancy` for a complete B-ary tree in breadth-first order
/// (children of node N at N*B+1 .. N*B+B); unused nodes have r < 0.
#include <iosfwd>
#include <string>

#include <icd/collision/sphere_tree.hpp>

namespace icd::collision {

/// Limits that protect the reader from absurd headers.
struct SphReadOptions {
  int max_levels = 16;            ///< largest accepted `levels`
  int max_branch = 64;            ///< largest accepted `branch`
  long long max_lines = 1 << 24;  ///< largest accepted (B^L-1)/(B-1)
};

/// Reads a `.sph` tree from a stream into the compact layout: unused nodes
/// (r < 0) are dropped, the remaining nodes keep breadth-first order, and
/// rest_spheres == spheres. `name` is used in error messages. A text after
/// the declared node lines whose first line does not start with a number
/// (the reference toolkit appends its options and evaluation so) is ignored.
/// Throws icd::InputError for a malformed header, a count of node lines that
/// differs from the header, non-numeric or non-finite values, an unused root,
/// or a used node below an unused parent. Memory grows only with the lines
/// actually read, never from the header count. A UTF-8 byte-order mark at the
/// start is skipped.
SphereTree read_sph(std::istream& in, const std::string& name = "<stream>",
                    const SphReadOptions& options = {});

/// Reads a `.sph` file (see read_sph(std::istream&...)); throws icd::InputError
/// if the file is missing, not a regular file, or larger than
/// icd::file_limits::kSph, before reading it.
SphereTree read_sph(const std::string& path, const SphReadOptions& options = {});

/// Writes `tree` (its current spheres) as `.sph`: levels = tree.num_levels(),
/// branch = `branch` or, when 0, the largest child count (at least 2). Missing
/// children are written as unused nodes `0 0 0 -1 0`; occupancy is written as 0.
/// Throws icd::ParameterError if a node has more than `branch` children.
void write_sph(std::ostream& out, const SphereTree& tree, int branch = 0);

/// Writes `tree` to a file; throws icd::InputError if it cannot be written.
void write_sph(const std::string& path, const SphereTree& tree, int branch = 0);

}  // namespace icd::collision
