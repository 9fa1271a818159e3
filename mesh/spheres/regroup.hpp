#pragma once
/// Regrouping the children of a tree level under their parents so that no
/// parent has more than a given number of children (the branching factor),
/// keeping the parents' spheres small.
#include <vector>

namespace icd::mesh {

/// Children i = 0 .. n-1 of a level, parents p = 0 .. m-1 of the level above;
/// reach[i][p] >= 0 is the radius parent p needs about its centre to cover
/// child i's samples (with margin). A parent's radius is the largest reach
/// of its children (0 without children); the objective is the sum of the
/// parents' radii.
///
/// Returns a parent for every child with at most `capacity` children per
/// parent: starting from `parent`, while a parent has too many children one
/// of them moves to a parent with room (the move with the smallest rise of
/// the objective); then single moves to a parent with room and swaps of two
/// children of different parents are made while they lower the objective
/// (at most `max_improvements` of them). A parent that has children keeps
/// at least one (a move never empties it). An assignment that already
/// respects the capacity is only improved, never made worse. Deterministic.
/// Throws ParameterError when n > m * capacity, capacity < 1, a parent index
/// is out of range, or the reach matrix is not n x m with finite entries >= 0.
std::vector<int> regroup_children(const std::vector<std::vector<double>>& reach,
                                  std::vector<int> parent, int capacity,
                                  int max_improvements = 10000);

/// The objective of regroup_children(): the sum over parents of the largest
/// reach of their children.
double regroup_cost(const std::vector<std::vector<double>>& reach, const std::vector<int>& parent,
                    int num_parents);

}  // namespace icd::mesh
