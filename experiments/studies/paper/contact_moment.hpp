#pragma once
/// Helpers shared by the paper and accuracy experiments: taking a scene run
/// to "the same moment of contact" (as table1 does), dense positions through
/// the rigid links, small command-line parsing helpers, and
/// the timing helpers of the error-against-run-time experiments.
#include <chrono>
#include <string>
#include <vector>

#include "experiments/common/timing.hpp"
#include "experiments/runner/run.hpp"

namespace icd::experiments {

/// Where run_to_contact() stopped.
struct ContactMoment {
  int contact_frame = -1;  ///< first frame (0-based) where a sphere pair produced a force; -1: none
  int last_frame = -1;  ///< the frame the world is at now (contact_frame + after, or the last run)
  std::vector<runner::FrameMetrics> frames;  ///< metrics of every frame run
};

/// Steps `world` (with its settings' collision budget) until `after` frames past first contact (active_pairs > 0), or
/// `max_frames` frames. The same rule as table1, so figures and tables
/// refer to the same moment.
ContactMoment run_to_contact(runner::World& world, int max_frames, int after);

/// Dense positions of object `o` (#N x 3) from its current coarse positions
/// through the rigid links (Eqs. 1, 9, 10).
MatX3d dense_positions(const runner::RuntimeObject& o);

/// Parses "a,b,c" into doubles; throws ParameterError naming `what` on a bad entry.
std::vector<double> parse_list(const std::string& text, const char* what);

}  // namespace icd::experiments
