#include <icd/coupling/world_settings.hpp>

#include <cmath>
#include <string>

#include <icd/mesh/core/error.hpp>

namespace icd::coupling {
namespace {

[[noreturn]] void fail(const std::string& field, const std::string& what, double value) {
  throw ParameterError("WorldSettings: " + field + ": " + what + ", got " + std::to_string(value));
}

}  // namespace

void validate(const WorldSettings& s) {
  if (!(s.frame_rate > 0) || !std::isfinite(s.frame_rate))
    fail("frame_rate", "must be > 0 and finite", s.frame_rate);
  if (!(s.target_fps >= 0) || !std::isfinite(s.target_fps))
    fail("target_fps", "must be >= 0 and finite (0 = off)", s.target_fps);
  if (!(s.min_query_budget > 0) || !std::isfinite(s.min_query_budget))
    fail("min_query_budget", "must be > 0 and finite", s.min_query_budget);
  if (s.threads < 0 || s.threads > 1024) fail("threads", "must be in 0..1024 (0 = all cores)", s.threads);
  if (!(s.worker_spin >= 0) || !(s.worker_spin <= 1))
    fail("worker_spin", "must be in [0, 1] s", s.worker_spin);
  if (!s.gravity.allFinite()) throw ParameterError("WorldSettings: gravity: must be finite");
  const CollisionSpec& c = s.collision;
  collision::validate(c.query);
  if (!(c.contact.stiffness > 0) || !std::isfinite(c.contact.stiffness))
    fail("collision.contact.stiffness", "must be > 0 and finite", c.contact.stiffness);
  if (!(c.deep_step_ratio >= 0) || !std::isfinite(c.deep_step_ratio))
    fail("collision.deep_step_ratio", "must be >= 0 and finite (0: off)", c.deep_step_ratio);
  if (!(c.previous_max_age >= 0))
    fail("collision.previous_max_age", "must be >= 0", c.previous_max_age);
  if (!(c.cycle_motion > 0) || !std::isfinite(c.cycle_motion))
    fail("collision.cycle_motion", "must be > 0 and finite", c.cycle_motion);
  if (!(c.update.margin >= 0) || !std::isfinite(c.update.margin))
    fail("collision.update.margin", "must be >= 0 and finite", c.update.margin);
}

}  // namespace icd::coupling
