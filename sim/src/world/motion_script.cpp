// SPDX-License-Identifier: MIT
// The motion scripts: hover, random walk on a segment, waypoints, teleport steps.
#include "wingman/sim/motion_script.hpp"

#include "trapezoid.hpp"
#include "wingman/sim/multirotor.hpp"

#include <wingman/common/config.hpp>
#include <wingman/geometry/angles.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::sim {
namespace {

using detail::PortableRandom;
using detail::Trapezoid;

std::string vec_text(const Eigen::Vector3d& v) { return fmt::format("[{}, {}, {}]", v.x(), v.y(), v.z()); }

/// One straight leg from rest to rest, then a pause.
struct Leg {
  double t_start = 0;  ///< s since frame 0
  Eigen::Vector3d from = Eigen::Vector3d::Zero();
  Eigen::Vector3d to = Eigen::Vector3d::Zero();
  Trapezoid profile{0, 1, 1};
  double pause_s = 0;
  double yaw_rad = 0;

  double t_end() const { return t_start + profile.duration() + pause_s; }
  MotionReference at(double t) const {
    const double tl = t - t_start;
    const Eigen::Vector3d d = to - from;
    const double length = d.norm();
    const Eigen::Vector3d dir = length > 0 ? Eigen::Vector3d(d / length) : Eigen::Vector3d::Zero();
    MotionReference r;
    r.p_in_world = tl >= profile.duration() ? to : Eigen::Vector3d(from + dir * profile.s(tl));
    r.v_in_world = dir * profile.v(tl);
    r.a_in_world = dir * profile.a(tl);
    r.yaw_rad = yaw_rad;
    return r;
  }
};

class HoverScript : public MotionScript {
 public:
  HoverScript(const Eigen::Vector3d& p, double yaw) {
    ref_.p_in_world = p;
    ref_.yaw_rad = yaw;
  }
  MotionReference at(double) override { return ref_; }
  std::optional<int64_t> end_utime() const override { return std::nullopt; }

 private:
  MotionReference ref_;
};

/// Legs between random points of the segment, generated on demand from the seed (in order, so the walk does not
/// depend on the query times).
class RandomWalkScript : public MotionScript {
 public:
  RandomWalkScript(const MotionSpec& spec, const Eigen::Vector3d& p_initial, double yaw)
      : spec_(spec), random_(spec.seed), yaw_(yaw) {
    const Eigen::Vector3d d = spec.segment_to - spec.segment_from;
    length_ = d.norm();
    s_ = length_ > 0 ? std::clamp((p_initial - spec.segment_from).dot(d) / length_, 0.0, length_) : 0.0;
  }
  MotionReference at(double t) override {
    while (legs_.empty() || legs_.back().t_end() <= t) add_leg();
    const auto it =
        std::upper_bound(legs_.begin(), legs_.end(), t, [](double x, const Leg& l) { return x < l.t_start; });
    return (it == legs_.begin() ? legs_.front() : *std::prev(it)).at(t);
  }
  std::optional<int64_t> end_utime() const override { return std::nullopt; }

 private:
  Eigen::Vector3d point(double s) const {
    if (length_ <= 0) return spec_.segment_from;
    return spec_.segment_from + (spec_.segment_to - spec_.segment_from) * (s / length_);
  }
  void add_leg() {
    Leg leg;
    leg.t_start = legs_.empty() ? 0.0 : legs_.back().t_end();
    const double goal = random_.uniform(0.0, length_);
    const double speed = random_.uniform(spec_.min_speed, spec_.max_speed);
    leg.from = point(s_);
    leg.to = point(goal);
    leg.profile = Trapezoid(std::abs(goal - s_), speed, spec_.accel);
    leg.pause_s = random_.uniform(0.0, spec_.max_pause_s);
    leg.yaw_rad = yaw_;
    // A leg of zero length and no pause would not advance time: give it the shortest pause.
    if (leg.profile.duration() + leg.pause_s <= 0) leg.pause_s = 1e-3;
    s_ = goal;
    legs_.push_back(leg);
  }

  MotionSpec spec_;
  PortableRandom random_;
  double yaw_;
  double length_ = 0;
  double s_ = 0;  ///< where the next leg starts, metres from segment_from
  std::vector<Leg> legs_;
};

class WaypointScript : public MotionScript {
 public:
  WaypointScript(const MotionSpec& spec, const Eigen::Vector3d& p_initial, double yaw, const FrameClock& clock)
      : clock_(clock) {
    Eigen::Vector3d from = p_initial;
    double t = 0;
    auto add = [&](const Waypoint& w, std::vector<Leg>& out) {
      Leg leg;
      leg.t_start = t;
      leg.from = from;
      leg.to = w.p_in_world;
      leg.profile = Trapezoid((w.p_in_world - from).norm(), w.speed, spec.accel);
      leg.pause_s = w.stop_s;
      if (w.yaw_rad) yaw = *w.yaw_rad;
      leg.yaw_rad = yaw;
      out.push_back(leg);
      t = leg.t_end();
      from = w.p_in_world;
    };
    for (const auto& w : spec.waypoints) add(w, first_pass_);
    first_pass_end_ = t;
    if (spec.loop) {
      // The loop: back to the first waypoint, then on to the last again; it repeats forever.
      for (size_t i = 0; i < spec.waypoints.size(); ++i) add(spec.waypoints[i], cycle_);
      cycle_period_ = t - first_pass_end_;
      if (cycle_period_ <= 0) cycle_.clear();  // every waypoint at one place, no stops: nothing moves
    }
    last_.p_in_world = from;
    last_.yaw_rad = yaw;
  }
  MotionReference at(double t) override {
    if (t < first_pass_end_) return find(first_pass_, t);
    if (cycle_.empty()) return first_pass_.empty() ? last_ : first_pass_.back().at(t);
    const double tc = first_pass_end_ + std::fmod(t - first_pass_end_, cycle_period_);
    return find(cycle_, tc);
  }
  std::optional<int64_t> end_utime() const override {
    if (!cycle_.empty()) return std::nullopt;
    return clock_.start_utime() + static_cast<int64_t>(std::ceil(first_pass_end_ * 1e6));
  }

 private:
  static MotionReference find(const std::vector<Leg>& legs, double t) {
    const auto it = std::upper_bound(legs.begin(), legs.end(), t, [](double x, const Leg& l) { return x < l.t_start; });
    return (it == legs.begin() ? legs.front() : *std::prev(it)).at(t);
  }

  FrameClock clock_;
  std::vector<Leg> first_pass_, cycle_;
  double first_pass_end_ = 0, cycle_period_ = 0;
  MotionReference last_;
};

/// Position i held from frame i * frames_per_step to frame (i + 1) * frames_per_step - 1; the step times are
/// FrameClock frame times, so the frames a step covers are exact.
class TeleportStepsScript : public MotionScript {
 public:
  TeleportStepsScript(const MotionSpec& spec, const Eigen::Vector3d& p_initial, double yaw, const FrameClock& clock)
      : spec_(spec), p_initial_(p_initial), yaw_(yaw), clock_(clock) {
    for (int i = 1; i < spec.steps; ++i) {
      boundaries_s_.push_back(clock.seconds_since_start(clock.utime(static_cast<int64_t>(i) * spec.frames_per_step)));
    }
  }
  MotionReference at(double t) override {
    const auto index = std::upper_bound(boundaries_s_.begin(), boundaries_s_.end(), t) - boundaries_s_.begin();
    MotionReference r;
    r.p_in_world = p_initial_ + spec_.step * static_cast<double>(index);
    r.yaw_rad = yaw_;
    return r;
  }
  std::optional<int64_t> end_utime() const override {
    return clock_.utime(static_cast<int64_t>(spec_.steps) * spec_.frames_per_step);
  }
  bool kinematic() const override { return true; }

 private:
  MotionSpec spec_;
  Eigen::Vector3d p_initial_;
  double yaw_;
  FrameClock clock_;
  std::vector<double> boundaries_s_;
};

}  // namespace

const char* motion_type_name(MotionSpec::Type type) {
  switch (type) {
    case MotionSpec::Type::kHover:
      return "hover";
    case MotionSpec::Type::kRandomWalk:
      return "random_walk";
    case MotionSpec::Type::kWaypoints:
      return "waypoints";
    case MotionSpec::Type::kTeleportSteps:
      return "teleport_steps";
  }
  return "unknown";
}

std::vector<std::string> validate_motion(const MotionSpec& spec, const Eigen::Vector3d& p_initial_in_world) {
  using common::problem;
  std::vector<std::string> p;
  auto positive = [&](const std::string& key, double value) {
    if (!(value > 0) || !std::isfinite(value)) p.push_back(problem(key, value, "must be > 0"));
  };
  switch (spec.type) {
    case MotionSpec::Type::kHover:
      break;
    case MotionSpec::Type::kRandomWalk: {
      if (!spec.segment_from.allFinite()) p.push_back(problem("from", vec_text(spec.segment_from), "must be finite"));
      if (!spec.segment_to.allFinite()) p.push_back(problem("to", vec_text(spec.segment_to), "must be finite"));
      positive("max_speed", spec.max_speed);
      positive("min_speed", spec.min_speed);
      if (spec.min_speed > spec.max_speed)
        p.push_back(problem("min_speed", spec.min_speed, fmt::format("must be <= max_speed ({})", spec.max_speed)));
      if (!(spec.max_pause_s >= 0) || !std::isfinite(spec.max_pause_s))
        p.push_back(problem("max_pause_s", spec.max_pause_s, "must be >= 0"));
      positive("accel", spec.accel);
      // The walk starts where the vehicle is: the initial position must lie on the segment (1 cm tolerance).
      const Eigen::Vector3d d = spec.segment_to - spec.segment_from;
      const double length = d.norm();
      const double s = length > 0 ? (p_initial_in_world - spec.segment_from).dot(d) / length : 0.0;
      const Eigen::Vector3d closest =
          spec.segment_from +
          (length > 0 ? Eigen::Vector3d(d / length * std::clamp(s, 0.0, length)) : Eigen::Vector3d::Zero());
      if (p.empty() && (p_initial_in_world - closest).norm() > 0.01) {
        p.push_back(fmt::format("from/to: the segment {} .. {} must contain the vehicle's initial.position {}",
                                vec_text(spec.segment_from), vec_text(spec.segment_to), vec_text(p_initial_in_world)));
      }
      break;
    }
    case MotionSpec::Type::kWaypoints:
      positive("accel", spec.accel);
      if (spec.waypoints.empty()) p.push_back("waypoints: must list at least one waypoint");
      for (size_t i = 0; i < spec.waypoints.size(); ++i) {
        const Waypoint& w = spec.waypoints[i];
        const std::string k = fmt::format("waypoints[{}].", i);
        if (!w.p_in_world.allFinite()) p.push_back(problem(k + "position", vec_text(w.p_in_world), "must be finite"));
        positive(k + "speed", w.speed);
        if (!(w.stop_s >= 0) || !std::isfinite(w.stop_s)) p.push_back(problem(k + "stop_s", w.stop_s, "must be >= 0"));
        if (w.yaw_rad && !std::isfinite(*w.yaw_rad)) p.push_back(problem(k + "yaw_deg", *w.yaw_rad, "must be finite"));
      }
      break;
    case MotionSpec::Type::kTeleportSteps:
      if (!spec.step.allFinite()) p.push_back(problem("step", vec_text(spec.step), "must be finite"));
      if (spec.steps < 1) p.push_back(problem("steps", spec.steps, "must be >= 1"));
      if (spec.frames_per_step < 1) p.push_back(problem("frames_per_step", spec.frames_per_step, "must be >= 1"));
      break;
  }
  return p;
}

std::unique_ptr<MotionScript> make_motion_script(const MotionSpec& spec, const Eigen::Vector3d& p_initial_in_world,
                                                 double yaw_initial_rad, const FrameClock& clock) {
  const auto problems = validate_motion(spec, p_initial_in_world);
  if (!problems.empty()) throw std::invalid_argument(problems.front());
  const double yaw = geometry::wrap_pi(yaw_initial_rad);
  switch (spec.type) {
    case MotionSpec::Type::kHover:
      return std::make_unique<HoverScript>(p_initial_in_world, yaw);
    case MotionSpec::Type::kRandomWalk:
      return std::make_unique<RandomWalkScript>(spec, p_initial_in_world, yaw);
    case MotionSpec::Type::kWaypoints:
      return std::make_unique<WaypointScript>(spec, p_initial_in_world, yaw, clock);
    case MotionSpec::Type::kTeleportSteps:
      return std::make_unique<TeleportStepsScript>(spec, p_initial_in_world, yaw, clock);
  }
  throw std::invalid_argument("motion type: unknown");
}

}  // namespace wingman::sim
