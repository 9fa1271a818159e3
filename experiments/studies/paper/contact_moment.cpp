#include "experiments/studies/paper/contact_moment.hpp"

#include <algorithm>
#include <cassert>
#include <sstream>

#include <icd/coupling/rigid_links.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::experiments {

ContactMoment run_to_contact(runner::World& world, int max_frames, int after) {
  ContactMoment cm;
  for (int f = 0; f < max_frames; ++f) {
    cm.frames.push_back(world.step());
    cm.last_frame = f;
    if (cm.contact_frame < 0 && cm.frames.back().active_pairs > 0) cm.contact_frame = f;
    if (cm.contact_frame >= 0 && f >= cm.contact_frame + after) break;
  }
  return cm;
}

MatX3d dense_positions(const runner::RuntimeObject& o) {
  MatX3d dense(o.asset.dense.V.rows(), 3);
  coupling::apply(o.asset.links, o.positions, dense);
  return dense;
}

std::vector<double> parse_list(const std::string& text, const char* what) {
  std::vector<double> out;
  std::stringstream ss(text);
  for (std::string t; std::getline(ss, t, ',');) {
    try {
      size_t used = 0;
      out.push_back(std::stod(t, &used));
      if (used != t.size()) throw std::invalid_argument(t);
    } catch (const std::exception&) {
      throw ParameterError(std::string(what) + ": not a number: \"" + t + "\"");
    }
  }
  if (out.empty()) throw ParameterError(std::string(what) + ": empty list");
  return out;
}

}  // namespace icd::experiments
