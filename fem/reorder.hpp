#pragma once
/// Renumbering of a tet mesh for memory locality of the element loops:
/// reverse Cuthill-McKee on the node graph, elements sorted by their
/// smallest new node index. Meshes from the preprocessing pipeline come in
/// generator order; after this the four node gathers of consecutive elements
/// hit nearby cache lines.
#include <vector>

#include <icd/mesh/core/types.hpp>

namespace icd::fem {

/// A renumbered mesh and the maps back to the input numbering.
struct ReorderedMesh {
  MatX3d V;                          ///< #V x 3, new node order
  MatX4i T;                          ///< #T x 4, new indices, same vertex order (orientation kept)
  std::vector<int> new_to_old_node;  ///< new node i is input node new_to_old_node[i]
  std::vector<int> old_to_new_node;  ///< inverse permutation
  std::vector<int> new_to_old_element;  ///< new element e is input element new_to_old_element[e]
};

/// Reverse Cuthill-McKee node order (each connected component started from a
/// pseudo-peripheral node, neighbours visited by increasing degree), then
/// elements stably sorted by their smallest new node index. Throws InputError
/// for an index out of range.
ReorderedMesh reorder_for_locality(const Eigen::Ref<const MatX3d>& V,
                                   const Eigen::Ref<const MatX4i>& T);

/// Largest |i - j| over node pairs sharing an element (the matrix bandwidth).
int node_bandwidth(const Eigen::Ref<const MatX4i>& T);

}  // namespace icd::fem
