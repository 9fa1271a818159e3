#pragma once
/// Penalty contact response between two sphere trees (paper 4.3, Eq. 11).
///
/// For each colliding sphere pair (COLLISIONLIST) and each untested pair
/// (PAIRLIST of an interrupted query, assumed colliding), the
/// penetration is delta = r_a + r_b - |O_b - O_a| and the repulsion direction
/// n = (O_b - O_a) / |O_b - O_a| (Eq. 11). Sphere b receives +k delta n and
/// sphere a receives -k delta n, so the two objects always receive exactly
/// opposite total forces. A sphere's force is passed to its associated coarse
/// nodes V_i (the same nodes that steer its update).
#include <limits>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <icd/collision/sphere_tree.hpp>
#include <icd/collision/traversal.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::coupling {

/// How a sphere's force reaches the coarse nodes.
enum class ContactDistribution {
  /// Each of the |V_i| nodes gets F / |V_i|; a node adds what it receives.
  /// Conserves momentum exactly (default).
  PartitionOfUnity,
  /// Node n of V_i gets F m_n / sum_{V_i} m (ContactOptions::mass_a/mass_b
  /// required): every node of the sphere accelerates alike, so the contact
  /// stiffness acts on the sphere's whole mass, not on its lightest node
  /// (far milder stability limit). Conserves momentum exactly.
  MassWeighted,
  /// The paper's wording: each node of V_i receives F and "averages the
  /// received forces" (sum / count). Does not conserve momentum when nodes
  /// receive different numbers of forces; kept for comparison.
  PaperAverage,
};

/// Options of the penalty response.
struct ContactOptions {
  double stiffness = 1e3;  ///< penalty stiffness k (N/m, > 0): force = k * penetration
  ContactDistribution distribution = ContactDistribution::PartitionOfUnity;
  /// Apply forces for the untested pairs (PAIRLIST of an interrupted query, or
  /// pairs held back by a depth or list cap), assumed colliding (paper 4.2).
  bool use_untested = true;
  /// Largest penetration credited to an untested pair (model units, > 0;
  /// inf = none, the paper). Untested pairs are coarse spheres assumed
  /// colliding; their overlap can be far deeper than the surfaces' (see
  /// runner's on_interrupt). Colliding leaf pairs are never capped.
  double max_untested_penetration = std::numeric_limits<double>::infinity();
  /// Direction used when two centres coincide (|O_b - O_a| < 1e-12 * (r_a + r_b)):
  /// normally the direction from object a's centroid to object b's. Normalised
  /// internally; a zero vector falls back to +z.
  Eigen::Vector3d coincident_direction{0.0, 0.0, 1.0};
  /// Lumped node masses of objects a and b (kg), for MassWeighted; also used
  /// to report ContactStats::max_rate. Not owned; may be null otherwise.
  const Eigen::VectorXd* mass_a = nullptr;
  const Eigen::VectorXd* mass_b = nullptr;
  /// Largest penalty rate a coarse node may receive (1/s^2; inf = no cap,
  /// the paper). A node's rate is the sum over its active pairs of
  /// k * share / m_n (see ContactStats::max_rate); with hundreds of leaf
  /// pairs on one node the summed stiffness far exceeds what an explicit
  /// cycle of length h keeps stable ((omega h)^2 = rate h^2 < 4). With a
  /// cap, every pair is weighted by w = min(1, cap / rate_n) over the nodes
  /// of both its spheres, so no node's rate exceeds the cap however many
  /// pairs it has, the forces stay equal and opposite pair by pair
  /// (momentum conserved) and nodes with few pairs keep the full k. Needs
  /// mass_a and mass_b. Not applied to PaperAverage.
  double node_rate_limit = std::numeric_limits<double>::infinity();
  /// With node_rate_limit: each node's rate over every pair it takes part
  /// in this cycle, of all object pairs (add_contact_rates() summed over
  /// them; #coarse nodes of a / b). The weights then hold a node touched by
  /// several objects at the cap in all (not at the cap per object pair).
  /// Null: this call's pairs only.
  const Eigen::VectorXd* total_rate_a = nullptr;
  const Eigen::VectorXd* total_rate_b = nullptr;
  /// When set (and both masses given): the node rates of the forces applied
  /// (weighted by the cap) are added to them (#coarse nodes of a / b), so a
  /// caller can sum them over object pairs (the stability bound of several
  /// pairs: World's softening).
  Eigen::VectorXd* applied_rate_a = nullptr;
  Eigen::VectorXd* applied_rate_b = nullptr;
};

/// What the response did.
struct ContactStats {
  int active_pairs = 0;        ///< pairs with positive penetration
  double max_penetration = 0;  ///< largest delta (model units)
  /// Colliding leaf pairs deeper than the smaller of their two radii
  /// (delta > min(r_a, r_b)): the surfaces have passed through each other by
  /// more than the spheres resolve (a contact found too late, or a penalty
  /// too soft for the load). Untested pairs are not counted.
  int deep_pairs = 0;
  /// Largest delta / min(r_a, r_b) over the colliding leaf pairs (> 1 when
  /// deep_pairs > 0).
  double max_depth_ratio = 0;
  /// Energy stored in the penalty springs, sum of k delta^2 / 2 over the
  /// active pairs (J when lengths are in m).
  double penalty_energy = 0;
  Eigen::Vector3d total_force_a = Eigen::Vector3d::Zero();  ///< sum of forces on object a
  Eigen::Vector3d total_force_b = Eigen::Vector3d::Zero();  ///< sum of forces on object b
  /// Largest added stiffness on one coarse node (k times the node's share of
  /// every active pair), for the FEM stable-step estimate (N/m).
  double max_node_stiffness = 0;
  /// Squared frequency of the penalty springs (1/s^2): per node n the sum
  /// over its active pairs of k * share_n / m_n (for MassWeighted k / M_i,
  /// M_i the mass of sphere i's nodes), maximised over each object's nodes
  /// and added for the two objects. A staggered response stays stable while
  /// sqrt(max_rate) h < 2. 0 unless both mass arrays were given.
  double max_rate = 0;
  /// Pairs whose force was weighted down by ContactOptions::node_rate_limit
  /// (w < 1), and the smallest weight (1: none).
  int capped_pairs = 0;
  double min_weight = 1;
};

/// What deep_contact_velocity_step did.
struct DeepContactStats {
  int pairs = 0;               ///< deep leaf pairs found
  int approaching = 0;         ///< of which approaching, in patches whose velocities changed (s > 0)
  double removed_energy = 0;   ///< kinetic energy taken out (J, >= 0)
};

/// The backstop of the penalty (not in the paper): colliding leaf pairs
/// deeper than `depth_ratio` times the smaller of their radii whose spheres
/// still approach each other along n = (O_b - O_a) / |O_b - O_a| (the
/// mass-weighted mean velocities of the two spheres' coarse nodes V_i, all
/// judged at the velocities on entry) get an inelastic velocity step. Each
/// such pair's impulse j n (on b, -j n on a, j = mu v_n: what would stop it
/// alone) is spread over its spheres' nodes in proportion to their masses.
/// Pairs sharing a coarse node (on either object) form a patch; a patch's
/// impulses are applied together, scaled by s = min(1, -G / H) (G the sum of
/// impulse . velocity, H of |impulse|^2 / m over its nodes), so they never
/// add kinetic energy (it changes by s G + s^2 H / 2 <= 0) and a lone pair
/// stops approaching exactly (s = 1). Momentum is conserved exactly (pair by
/// pair); there is no tangential impulse beyond the pairs' normals; the
/// result depends neither on the order of the pairs nor on which object is
/// a: a mirror-image pair gets mirror-image velocities. (The step pair by
/// pair, one after the other, did not: with collision.cycles_at_fem_step
/// HeadOn's spheres left with 2.07 % sideways drift, 1.48 % with this one.)
/// mass_a / mass_b: lumped node masses; vel_a / vel_b: node velocities,
/// changed in place. Throws ParameterError on missing associations or
/// masses of the wrong size.
DeepContactStats deep_contact_velocity_step(const collision::SphereTree& a,
                                            const collision::SphereTree& b,
                                            const collision::CollisionResult& result,
                                            const Eigen::VectorXd& mass_a,
                                            const Eigen::VectorXd& mass_b, Eigen::Ref<MatX3d> vel_a,
                                            Eigen::Ref<MatX3d> vel_b, double depth_ratio = 1.0);

/// The sphere -> coarse node map of one object as a sparse matrix
/// D (#coarse nodes x #spheres): column i holds 1/|V_i| on the nodes of V_i,
/// so node_forces = D * sphere_forces (PartitionOfUnity).
Eigen::SparseMatrix<double> sphere_to_node_matrix(const collision::SphereTree& tree,
                                                  int num_coarse_nodes);

/// Adds to rate_a / rate_b (#coarse nodes of a / b) each node's penalty
/// rate k share / m_n, at the full stiffness, of the pairs of `result` that
/// respond (as apply_contact_forces(): colliding pairs, and untested ones
/// with use_untested, at most max_untested_penetration deep): summed over
/// the object pairs of a cycle, the totals ContactOptions::total_rate_a/b
/// weigh against. Needs mass_a and mass_b; throws ParameterError as
/// apply_contact_forces() for missing associations or masses.
void add_contact_rates(const collision::SphereTree& a, const collision::SphereTree& b,
                       const collision::CollisionResult& result, const ContactOptions& options,
                       Eigen::VectorXd& rate_a, Eigen::VectorXd& rate_b);

/// Computes penalty forces for the pairs of `result` between trees a and b
/// (current spheres) and adds them to forces_a (#coarse nodes of a x 3) and
/// forces_b. Throws ParameterError for a non-positive stiffness, missing
/// sphere associations, out-of-range node indices, or MassWeighted without
/// masses (or with a non-positive mass).
ContactStats apply_contact_forces(const collision::SphereTree& a, const collision::SphereTree& b,
                                  const collision::CollisionResult& result,
                                  const ContactOptions& options, Eigen::Ref<MatX3d> forces_a,
                                  Eigen::Ref<MatX3d> forces_b);

}  // namespace icd::coupling
