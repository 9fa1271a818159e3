#pragma once
/// Fast evaluation of the rigid links (paper section 3.2, Eqs. 1, 9, 10).
///
/// Many dense vertices share the same ordered coarse node triple (q0, q1, q2)
/// (measured: 3.9-10.5 links per triple on the bunny and dragon bundles of
/// 2026-11-21 09:45, 2.1-5.0 on the older ones).
/// LinkEvaluator numbers the distinct triples once; each apply() then
///   1. gathers each triple's nodes into a per-triple table and computes its
///      deformed frame (e0, e1, e2) of Eqs. 4-6 on two triples at a time
///      (SSE2 packets through Eigen, square roots included; one division per
///      triple: 1/|a| = 1/(|u| |n|), 1/|n| = |u|/|a|, 1/|u| = |n|/|a|);
///   2. evaluates every link, in dense-vertex order, as the triple's 3 x 6
///      matrix times the link's six stored numbers,
///        p = [q0 q1 q2 | e0 e1 e2] (alpha_0, alpha_1, alpha_2, c_0, c_1, c_2)^T,
///      summed in the order of apply_reference(), on (x, y, z, pad) packets.
/// Results equal apply_reference() to rounding (measured <= 2e-16 relative;
/// the reciprocals above are the only difference).
///
/// Degenerate frames. When the deformed triangle (q0, q1, q2) is degenerate
/// (|n| <= degenerate_tolerance * |q1 - q0| * |q2 - q0|: collinear or
/// coincident nodes) the frame of Eqs. 4-6 is undefined. The evaluator then
/// uses a fallback frame that is orthonormal and right-handed like Eqs. 4-6
/// (e2 = e0 x e1), so every link keeps its length |c| (no NaN, no collapse):
///   - if q0 != q1: e1 = (q0 - q1) / |q0 - q1| as usual; e0 is the previous
///     frame's e0 (or, if that is nearly parallel to e1, its e2) made
///     orthogonal to e1 and normalised; e2 = e0 x e1. The previous frame is
///     the one this triple got at its last apply(), regular or fallback (the
///     state kept by the evaluator); a triple without one (degenerate at its
///     first apply(), or after reset_frames()) starts from the coordinate
///     axis least aligned with e1.
///   - if q0 == q1 (or |q0 - q1|^2 overflows): the previous frame is kept
///     unchanged (the identity frame if there is none).
/// The number of degenerate triples and of links they carry is returned, so a
/// caller's health check can react.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include <icd/coupling/rigid_links.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::coupling {

/// Options of LinkEvaluator.
struct LinkEvaluatorOptions {
  /// A deformed frame is degenerate when |n| <= degenerate_tolerance *
  /// |q1 - q0| * |q2 - q0|, i.e. when the sine of the triangle's angle at q0 is
  /// at most this (dimensionless, in [0, 1)); also when an edge is zero. Near
  /// that limit the frame of Eqs. 4-6 loses orthogonality like 1e-16 / sine
  /// (1e-10 at the default), so smaller values follow apply_reference() into
  /// noisier frames. Links are built with sines >= ~1e-3 (RigidLinkOptions).
  double degenerate_tolerance = 1e-6;
};

/// What LinkEvaluator::apply() met.
struct LinkApplyResult {
  int degenerate_triples = 0;  ///< triples that used the fallback frame this call
  int degenerate_links = 0;    ///< dense vertices carried by those triples
};

/// The rigid links of one object, grouped by coarse node triple for fast
/// per-frame evaluation. Build once per RigidLinks (a hash of the triples,
/// O(N); memory 52 bytes per link plus ~210 per distinct triple), then call
/// apply() every frame. apply() allocates nothing. Not thread-safe: apply()
/// updates the per-triple frame state used by the degenerate-frame fallback.
class LinkEvaluator {
 public:
  LinkEvaluator() = default;

  /// Groups `links` (checked with validate()) by node triple. Throws InputError
  /// when the links are inconsistent, ParameterError on a bad option.
  explicit LinkEvaluator(const RigidLinks& links, const LinkEvaluatorOptions& options = {});

  /// Evaluates every link (Eqs. 1, 9, 10) for the current coarse positions
  /// (#M x 3, M == num_coarse_nodes()) into dense_out (#N x 3, N ==
  /// num_links(); not resized, must already have N rows). Equal to
  /// apply_reference() to rounding wherever no frame is degenerate; see the file
  /// comment for degenerate frames. Throws ParameterError on a size mismatch,
  /// NumericalError naming the node when a linked coarse node is not finite
  /// (dense_out is then left unspecified).
  LinkApplyResult apply(const Eigen::Ref<const MatX3d>& coarse_positions,
                        Eigen::Ref<MatX3d> dense_out);

  /// As apply(), for the links of the listed triples only (indices in
  /// [0, num_triples()), no repeats, any order): their rows of dense_out are
  /// written, bitwise equal to what apply() writes there (the same
  /// arithmetic, lane by lane); the other rows are left as they are. Only
  /// the listed triples' frame state is updated. For callers that need a
  /// few links, e.g. the dense vertices near a static obstacle.
  LinkApplyResult apply_triples(const Eigen::Ref<const MatX3d>& coarse_positions,
                                const std::vector<int32_t>& triples, Eigen::Ref<MatX3d> dense_out);

  /// As apply_triples(), writing only the listed links (each a link of one
  /// of the listed triples, any order): their rows bitwise equal to what
  /// apply() writes there, the other rows left as they are. ParameterError
  /// for a link outside [0, num_links()) or not of a listed triple. For
  /// callers that can tell from the coarse nodes which vertices they need.
  LinkApplyResult apply_links(const Eigen::Ref<const MatX3d>& coarse_positions,
                              const std::vector<int32_t>& triples,
                              const std::vector<int32_t>& links, Eigen::Ref<MatX3d> dense_out);

  /// The triple of link k (its index in [0, num_triples())).
  int32_t link_triple(int k) const { return m_link_triple[static_cast<size_t>(k)]; }

  /// Forgets the frame state: the next apply() behaves as on a new evaluator.
  void reset_frames();

  int num_links() const { return static_cast<int>(m_link_triple.size()); }
  int num_coarse_nodes() const { return m_num_coarse_nodes; }
  /// Number of distinct ordered node triples (q0, q1, q2) among the links.
  int num_triples() const { return static_cast<int>(m_links_per_triple.size()); }
  /// The three coarse node indices (q0, q1, q2) of triple t.
  const int32_t* triple_nodes(int t) const { return &m_triple_nodes[3 * static_cast<size_t>(t)]; }
  /// The links of triple t, ascending: [links_of_triple(t), links_of_triple(t + 1)) of
  /// triple_links().
  int32_t links_of_triple(int t) const { return m_triple_offset[static_cast<size_t>(t)]; }
  const std::vector<int32_t>& triple_links() const { return m_triple_links; }

 private:
  /// The size checks of apply() and apply_triples() (`who` names the caller).
  void check_sizes(const char* who, Eigen::Index coarse_rows, Eigen::Index dense_rows) const;
  void check_finite(const Eigen::Ref<const MatX3d>& coarse_positions) const;
  /// The size checks (`who` names the caller), each listed triple in
  /// range, then their frames (update_triples).
  LinkApplyResult update_listed(const char* who, const Eigen::Ref<const MatX3d>& coarse_positions,
                                const std::vector<int32_t>& triples,
                                const Eigen::Ref<MatX3d>& dense_out);
  /// Frames of the triples index(0), ..., index(count - 1).
  template <class Index>
  LinkApplyResult update_triples(const Eigen::Ref<const MatX3d>& coarse_positions, int count,
                                 Index index);
  void fallback_frame(int t);
  void evaluate_links(Eigen::Ref<MatX3d> dense_out) const;

  LinkEvaluatorOptions m_options;
  int32_t m_num_coarse_nodes = 0;
  /// #T x 3, row-major: node indices q0, q1, q2 of each distinct triple, in
  /// order of first use by the links.
  std::vector<int32_t> m_triple_nodes;
  std::vector<int32_t> m_links_per_triple;  ///< #T
  std::vector<int32_t> m_link_triple;       ///< #N: triple of each link
  /// The links of each triple, ascending (#N), and where each triple's start
  /// (#T + 1).
  std::vector<int32_t> m_triple_links, m_triple_offset;
  /// 6 x #N (column k: alpha_k0..2, c_k0..2 of link k).
  Eigen::Matrix<double, 6, Eigen::Dynamic> m_weights;
  /// 24 x #T, column t: q0, q1, q2, e0, e1, e2 of triple t, each padded to 4
  /// doubles (aligned packets). The frame part is the state kept between calls.
  Eigen::Matrix<double, 24, Eigen::Dynamic> m_table;
  std::vector<char> m_has_frame;  ///< #T: m_table holds a frame of this triple
  /// #T: the apply_links() call that last updated each triple's frame
  /// (that call's number, m_calls), so a link of another triple is refused.
  std::vector<uint32_t> m_updated_in;
  uint32_t m_calls = 0;
};

}  // namespace icd::coupling
