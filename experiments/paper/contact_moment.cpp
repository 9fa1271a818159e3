#include "experiments/paper/contact_moment.hpp"

#include <algorithm>
#include <cassert>
#include <sstream>

#include "coupling/rigid_links.hpp"
#include "mesh/io/error.hpp"

namespace icd::experiments {

ContactMoment run_to_contact(runner::World& world, int max_frames, int after, double budget) {
  ContactMoment cm;
  for (int f = 0; f < max_frames; ++f) {
    cm.frames.push_back(world.step(budget));
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

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double median(std::vector<double> v) {
  assert(!v.empty());
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
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
