#pragma once
/// Helpers shared by the paper and accuracy experiments: taking a scene run
/// to "the same moment of contact" (as table1 does), dense positions through
/// the rigid links, small command-line parsing helpers, and
/// the timing helpers of the error-against-run-time experiments.
#include <chrono>
#include <string>
#include <vector>

#include "experiments/runner/world.hpp"

namespace icd::experiments {

/// Where run_to_contact() stopped.
struct ContactMoment {
  int contact_frame = -1;  ///< first frame (0-based) where a sphere pair produced a force; -1: none
  int last_frame = -1;  ///< the frame the world is at now (contact_frame + after, or the last run)
  std::vector<runner::FrameMetrics> frames;  ///< metrics of every frame run
};

/// Steps `world` (collision budget `budget` s per query; negative: the
/// scene's) until `after` frames past first contact (active_pairs > 0), or
/// `max_frames` frames. The same rule as table1, so figures and tables
/// refer to the same moment.
ContactMoment run_to_contact(runner::World& world, int max_frames, int after, double budget = -1);

/// Dense positions of object `o` (#N x 3) from its current coarse positions
/// through the rigid links (Eqs. 1, 9, 10).
MatX3d dense_positions(const runner::RuntimeObject& o);

/// Wall seconds elapsed since `t0` (steady clock).
double seconds_since(std::chrono::steady_clock::time_point t0);

/// The upper median of `v` (the element at index size/2 once sorted).
/// Precondition: `v` is not empty.
double median(std::vector<double> v);

/// Parses "a,b,c" into doubles; throws ParameterError naming `what` on a bad entry.
std::vector<double> parse_list(const std::string& text, const char* what);

}  // namespace icd::experiments
