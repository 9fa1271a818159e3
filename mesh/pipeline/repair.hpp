#pragma once
/// Stage 1 of the preprocessing pipeline (issue 4): turn a raw triangle soup
/// into a closed, manifold, outward-oriented, non-self-intersecting surface,
/// or refuse it with an InputError that says where it fails.
#include <string>

#include <icd/mesh/core/types.hpp>

namespace icd::mesh {

/// Options of repair_surface().
struct RepairOptions {
  /// Holes whose boundary loop has at most this many edges are filled...
  int max_hole_edges = 200;
  /// ...and whose diameter (largest distance between two loop vertices) is at
  /// most this fraction of the bounding-box diagonal. Larger holes are refused.
  /// (1: any size; a filled hole wider than 0.1 of the diagonal is reported.)
  double max_hole_diameter = 1.0;
  /// Refine and fair the hole patch (CGAL triangulate_refine_and_fair_hole);
  /// false: plain minimal-area triangulation (triangulate_hole).
  bool fair_holes = true;
  /// A mesh whose enclosed volume is below this fraction of diagonal^3 is refused.
  double min_volume_fraction = 1e-9;
  /// Self-intersection check (CGAL does_self_intersect); disabling it is only
  /// for callers that check themselves.
  bool check_self_intersections = true;
  /// Try CGAL's local self-intersection repair (experimental::remove_self_intersections:
  /// removes the faces around each intersection and re-fills the hole) before refusing.
  bool remove_self_intersections = true;
  /// Resolve self-intersections first by CGAL's autorefinement
  /// (experimental::autorefine_and_remove_self_intersections): the union of
  /// the overlapping parts; the region enclosed does not change.
  bool autorefine = true;
  /// Largest relative change of area or volume the local repair may make
  /// (changes above 0.5 % are reported).
  double max_surface_change = 0.05;
  /// What to do when the surface cannot be made clean by the steps above (a
  /// non-manifold edge, self-intersections that neither autorefinement nor
  /// the local repair resolve): rebuild it by CGAL's 3D alpha wrapping (a
  /// closed, manifold, intersection-free surface enclosing the input at
  /// distance `wrap_offset`, bridging gaps narrower than `wrap_alpha`).
  enum class Wrap {
    never,     ///< refuse, naming the cause and the option --wrap
    fallback,  ///< wrap only what would otherwise be refused (the default)
    always,    ///< wrap every input (after welding), skipping steps 5-9
  };
  Wrap wrap = Wrap::fallback;
  double wrap_alpha = 0.01;   ///< alpha, a fraction of the bounding-box diagonal (> 0)
  double wrap_offset = 0.0;   ///< offset, fraction of the diagonal; 0: wrap_alpha / 30
  /// A wrap with a point farther than this fraction of the diagonal from the
  /// input (approximate one-sided distance, wrap to input: surfaces of the
  /// input inside the wrap, e.g. overlapping parts, do not count) is refused, naming
  /// --wrap-alpha (a smaller alpha follows the input more closely) and
  /// --max-wrap-distance (this limit). A wrap that closes holes or tunnels
  /// lies about their radius away.
  double max_wrap_distance = 0.03;
};

/// "never", "fallback" or "always"; anything else throws ParameterError naming `field`.
RepairOptions::Wrap parse_wrap(const std::string& name, const std::string& field = "wrap");
const char* to_string(RepairOptions::Wrap wrap);

/// What repair_surface() did, in counts.
struct RepairReport {
  int input_vertices = 0, input_faces = 0;
  int merged_duplicate_vertices = 0;  ///< vertices with exactly equal coordinates merged
  int removed_degenerate_faces = 0;   ///< repeated vertex or zero area
  int removed_duplicate_faces = 0;    ///< same vertex set as an earlier face
  int removed_unreferenced_vertices = 0;
  int reoriented_faces = 0;          ///< faces flipped to make orientation consistent
  bool reversed_to_outward = false;  ///< whole surface (or components) flipped outward
  int holes_filled = 0;
  int hole_faces_added = 0;
  int split_nonmanifold_vertices = 0;   ///< vertex copies made to split fans touching at a point
  double largest_hole_filled = 0.0;     ///< diameter / bbox diagonal of the largest filled hole
  int self_intersections_autorefined = 0;  ///< intersecting face pairs resolved by autorefinement
  double area_removed_inside = 0.0;        ///< area fraction the autorefinement dropped (inside)
  int self_intersections_repaired = 0;  ///< intersecting face pairs removed by local repair
  double area_change = 0.0;             ///< relative area change of the local repair
  double volume_change = 0.0;           ///< relative volume change of the local repair
  /// Why the surface was rebuilt by alpha wrapping: 0 not wrapped, 1 a
  /// non-manifold edge, 2 unresolved self-intersections, 3 asked (--wrap always),
  /// 4 the mesher failed on the repaired surface, 5 distinct components of
  /// the repaired surface lie closer than the mesher's surface tolerance (4
  /// and 5 are set by preprocess()'s automatic wrap retry, never by
  /// repair_surface()).
  int wrap_cause = 0;
  double wrap_alpha = 0.0;     ///< alpha used, fraction of the diagonal
  double wrap_distance = 0.0;  ///< largest distance wrap -> input / diagonal (approximate)
  /// Volume the input encloses when it was wrapped and is a closed, consistently
  /// oriented surface (model units^3, as `volume`); else 0 (not known).
  double input_volume = 0.0;
  int components = 0;                   ///< connected components of the output
  int output_vertices = 0, output_faces = 0;
  double volume = 0.0;  ///< enclosed volume of the output (model units^3)

  /// One line per non-zero count, for the tool's summary.
  std::string to_string() const;
};

/// Result of repair_surface().
struct RepairResult {
  SurfaceMesh mesh;  ///< closed, manifold, outward-oriented, no self-intersection
  RepairReport report;
};

/// Repairs `input` (V #V x 3, F #F x 3; orientation and duplicates arbitrary):
/// merges exactly duplicated vertices, removes degenerate and duplicate faces
/// and unreferenced vertices, orients the faces consistently (CGAL
/// orient_polygon_soup), fills holes below the size limits, orients each
/// component outward (CGAL orient_to_bound_a_volume).
/// Throws InputError, prefixed with `name`, when the input has out-of-range
/// indices or non-finite coordinates, is flat (zero volume), has a
/// non-manifold edge or vertex (named, with its position), keeps boundary
/// loops after hole filling (count, size, a vertex on the largest), or
/// self-intersects after the local repair (number of intersecting face pairs
/// and the first pair).
RepairResult repair_surface(const SurfaceMesh& input, const RepairOptions& options = {},
                            const std::string& name = "surface");

}  // namespace icd::mesh
