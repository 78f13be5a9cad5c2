#include "sowing_robot/core/settings/node_settings.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <sstream>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

const ParamTable<RunSettings>& RunSettings::table() {
  using S = RunSettings;
  static const ParamTable<S> table({
      choice("mode", &S::lockstep, false, {{"realtime", false}, {"lockstep", true}},
             "realtime: paced to the wall clock; lockstep: each step waits for its torque (sim.launch picks "
             "lockstep when headless)"),
      number("control_rate", &S::control_rate, 1000.0, Limits::closed(1.0, 100000.0), "Hz",
             "plant step and control rate; every message is stamped on its grid"),
      number("duration", &S::duration, 25.0, Limits::closed(0.0, 1e7), "s",
             "scenario length: lockstep stops there and run_monitor reports; 0 = forever"),
      text("odom_frame", &S::odom_frame, "odom", "world-fixed frame of odom, paths and markers (REP-105)"),
      text("base_frame", &S::base_frame, "base_link", "the robot's frame: the axle midpoint (REP-105)"),
      number("start/x", &S::start_x, -1.0, Limits::any(), "m",
             "initial x of the axle midpoint (thesis 5.3); the field's approach starts here too"),
      number("start/y", &S::start_y, 0.0, Limits::any(), "m", "initial y of the axle midpoint"),
      number("start/theta", &S::start_theta, 0.0, Limits::any(), "rad", "initial heading"),
  });
  return table;
}

RunSettings::RunSettings() { table().applyDefaults(*this); }

std::int64_t RunSettings::periodNs() const { return static_cast<std::int64_t>(std::llround(1e9 / control_rate)); }

const ParamTable<PlantSimSettings>& PlantSimSettings::table() {
  using S = PlantSimSettings;
  static const ParamTable<S> table = [] {
    ParamTable<S> t({
        number("realtime_factor", &S::realtime_factor, 1.0, Limits::closed(0.01, 1000.0), "",
               "realtime mode: simulated seconds per wall second"),
        number("torque_timeout", &S::torque_timeout, 0.1, Limits::positive(), "s",
               "realtime: an older wheel_torque is replaced by zero torque (simulated time)"),
        number("publish_rate", &S::publish_rate, 50.0, Limits::closed(0.1, 1000.0), "Hz",
               "tf, joint_states and travelled_path (simulated time); odom goes out every step"),
        number("clock_rate", &S::clock_rate, 100.0, Limits::closed(0.0, 1e6), "Hz",
               "/clock (simulated time); 0 = every step. Controllers use header stamps, so a lower rate only "
               "coarsens log, rosbag and rviz time"),
        number("lockstep_retry", &S::lockstep_retry, 0.5, Limits::positive(), "s",
               "lockstep: re-publish the state when no torque came (wall time)"),
        number("lockstep_timeout", &S::lockstep_timeout, 5.0, Limits::positive(), "s",
               "lockstep: report the missing input after this (wall time)"),
        number("lockstep_give_up", &S::lockstep_give_up, 120.0, Limits::nonNegative(), "s",
               "lockstep: exit 3 naming the missing input after waiting this long (wall time); 0 = never"),
        integer("min_subscribers", &S::min_subscribers, 3, Limits::closed(0, 100), "",
                "lockstep: subscribers to wait for before step 0, of ground_truth plus (loop_topic odom) of odom"),
        text("wait_for", &S::wait_for, "",
             "lockstep: space-separated names of the nodes (or nodelets) that must have announced themselves "
             "on `ready` before step 0; empty = none"),
        text("loop_topic", &S::loop_topic, "ground_truth",
             "the plant topic the controllers' feedback comes from (sim.launch feedback:=): its subscribers "
             "count toward min_subscribers",
             {"ground_truth", "odom"}),
        number("startup_delay", &S::startup_delay, 0.5, Limits::nonNegative(), "s",
               "lockstep: settle time before step 0 (wall time)"),
        number("max_speed", &S::max_speed, 20.0, Limits::positive(), "m/s",
               "|v| beyond this (or a non-finite state) stops the run as diverged (exit 2)"),
        flag("exit_at_end", &S::exit_at_end, false, "lockstep: exit when the scenario ends"),
        flag("start_at_route", &S::start_at_route, false,
             "start where reference_generator's coverage route begins (type coverage: the route's start, or the "
             "fleet robot's start pose, ros/coverage_route.h), planned from reference_generator's keys, in place "
             "of run/start (sim.launch sets it with field_file:=)"),
    });
    return t.nest("", &S::disturbance, disturbanceTable());
  }();
  return table;
}

PlantSimSettings::PlantSimSettings() { table().applyDefaults(*this); }

std::vector<std::string> PlantSimSettings::waitForNames() const {
  std::vector<std::string> names;
  std::istringstream words(wait_for);
  for (std::string name; words >> name;) names.push_back(name);
  return names;
}

std::string PlantSimSettings::validate() const {
  std::string names_error;
  for (const std::string& name : waitForNames()) {
    // A node's base name (ros/common/ready_roster.h announcedName): a letter, then letters, digits, '_'.
    const bool valid = std::isalpha(static_cast<unsigned char>(name[0])) &&
                       std::all_of(name.begin(), name.end(),
                                   [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
    if (!valid) {
      names_error = "wait_for: '" + name + "' is not a node base name (a letter, then letters, digits or _)";
      break;
    }
  }
  return firstError({table().checkRanges(*this), names_error, disturbance.validate()});
}

namespace {

/// The slot's controller parameters as entries of a node's table (controller_factory.h: every registered
/// controller's, a table shared by two controllers once): the thesis controller's (the slot's first)
/// unmarked, another's meaning marked with the controllers it acts in ("[pid]", "[pure_pursuit, rpp]"); a key
/// in two tables (max_torque: the motors' one limit) is one entry that sets both.
template <typename S>
void addControllerParams(ParamTable<S>& table, ControllerParam::Slot slot) {
  const std::string thesis =
      slot == ControllerParam::Slot::outer ? outerChoices().front().first : innerChoices().front().first;
  std::vector<ParamEntry<S>> entries;
  for (const ControllerParam& p : slotParams(slot)) {
    auto same =
        std::find_if(entries.begin(), entries.end(), [&](const ParamEntry<S>& e) { return e.info.key == p.info->key; });
    if (same != entries.end()) {
      same->set = [set = same->set, also = p.set](S& s, const ParamValue& v) {
        set(s, v);
        also(s, v);
      };
      continue;
    }
    ParamEntry<S> e{*p.info, [get = p.get](const S& s) { return get(s); },
                    [set = p.set](S& s, const ParamValue& v) { set(s, v); }};
    const std::vector<std::string> acting = controllersActingOn(slot, p.info);
    if (std::find(acting.begin(), acting.end(), thesis) == acting.end()) {
      std::string mark;
      for (const std::string& name : acting) mark += (mark.empty() ? "[" : ", ") + name;
      e.info.meaning = mark + "] " + e.info.meaning;
    }
    entries.push_back(std::move(e));
  }
  for (ParamEntry<S>& e : entries) table.add(std::move(e));
}

}  // namespace

const ParamTable<KinematicControllerSettings>& KinematicControllerSettings::table() {
  using S = KinematicControllerSettings;
  static const ParamTable<S> table = [] {
    ParamTable<S> t({
        choice("outer", static_cast<OuterKind S::*>(&S::outer), OuterKind::kanayama, outerChoices(),
               "the outer controller: Kanayama (eqs 4.1-4.2), pure pursuit, or nav2's Regulated Pure Pursuit; "
               "the parameters of the others are checked but inert"),
        number("input_timeout", &S::input_timeout, 0.05, Limits::positive(), "s",
               "realtime: a reference older than this commands a stop (simulated time); shorter than "
               "torque_controller's, so a silent reference generator is reported as such"),
    });
    addControllerParams(t, ControllerParam::Slot::outer);
    t.nest("", &S::limits, commandLimitsTable());  // whichever controller runs
    return t;
  }();
  return table;
}

KinematicControllerSettings::KinematicControllerSettings() { table().applyDefaults(*this); }

std::string KinematicControllerSettings::validate() const {
  return firstError({table().checkRanges(*this), validateSlot(*this, ControllerParam::Slot::outer), limits.validate()});
}

const ParamTable<TorqueControllerSettings>& TorqueControllerSettings::table() {
  using S = TorqueControllerSettings;
  static const ParamTable<S> table = [] {
    ParamTable<S> t({
        choice("inner", static_cast<InnerKind S::*>(&S::inner), InnerKind::sliding_mode, innerChoices(),
               "the inner controller: the sliding-mode controller (atsmc or tsmc by `mode`) or the wheel-velocity "
               "PID; the parameters of the other are checked but inert"),
        number("input_timeout", &S::input_timeout, 0.1, Limits::positive(), "s",
               "realtime: a desired_velocity older than this gives zero torque; the sliding integrals (PID: "
               "its integrals) restart when it returns (simulated time)"),
    });
    addControllerParams(t, ControllerParam::Slot::inner);
    t.nest("", &S::hold, standstillHoldTable());  // whichever controller runs
    return t;
  }();
  return table;
}

TorqueControllerSettings::TorqueControllerSettings() { table().applyDefaults(*this); }

std::string TorqueControllerSettings::validate() const {
  return firstError({table().checkRanges(*this), validateSlot(*this, ControllerParam::Slot::inner), hold.validate()});
}

const ParamTable<ReferenceGeneratorSettings>& ReferenceGeneratorSettings::table() {
  using S = ReferenceGeneratorSettings;
  static const ParamTable<S> table({
      choice("type", &S::type, S::Type::kLine,
             {{"line", S::Type::kLine},
              {"field", S::Type::kField},
              {"path", S::Type::kPath},
              {"coverage", S::Type::kCoverage}},
             "line: the thesis's sowing line of Table 5.2; field: rows and headland turns (config/field*.yaml) "
             "followed by the potential field or the path follower (field/follower); "
             "path: a given path (path/points, or nav_msgs/Path on `path`) with a speed profile (config/path.yaml); "
             "coverage: the field of field_file planned by the coverage planner (coverage/..., config/coverage.yaml) "
             "and its route followed by the path follower from run/start"),
      number("line/x0", &S::line_x0, 0.0, Limits::any(), "m", "type line: x_d = x0 + v_r t"),
      number("line/v_r", &S::line_v_r, 1.0, Limits::closed(0.0, 10.0), "m/s", "type line: reference speed v_r"),
      number("line/y", &S::line_y, 3.0, Limits::any(), "m", "type line: y_d"),
      text("field_file", &S::field_file, "",
           "type coverage: the field file, GeoJSON in WGS84 or a local-frame YAML (docs/field_file.md), in the odom "
           "frame"),
      text("field_origin", &S::field_origin, "",
           "type coverage, a GeoJSON file: the local frame's origin LAT,LON[,ALT] [deg, deg, m] in place of the "
           "file's \"origin\"; \"\": the file's"),
      number("path_spacing", &S::path_spacing, 0.1, Limits::positive(), "m", "distance between reference_path points"),
      number("lookahead", &S::lookahead, 0.05, Limits::closed(1e-6, 10.0), "s",
             "references are sent this far ahead of /clock, so the loop never waits for this node; obstacle and "
             "gain changes apply this much later"),
  });
  return table;
}

ReferenceGeneratorSettings::ReferenceGeneratorSettings() { table().applyDefaults(*this); }

const ParamTable<SeedDrillSettings>& SeedDrillSettings::table() {
  using S = SeedDrillSettings;
  static const ParamTable<S> table = [] {
    ParamTable<S> t({
        text("tool_link", &S::tool_link, "tool_link", "URDF link of the seed-drop point"),
        flag("follow_hitch", &S::follow_hitch, false,
             "sow only while torque_controller's hitch control leaves the tool down (WheelTorque/tool_raised on "
             "wheel_torque, paired by stamp with the state and the reference; sim.launch sets it); false: the "
             "reference's tool_down alone (no torque_controller)"),
        number("marker_size", &S::marker_size, 0.04, Limits::closed(0.005, 1.0), "m",
               "diameter of the seeds' spheres in rviz (display only; fleet.launch shows them larger, to be seen "
               "at the scale of the whole field)"),
    });
    return t.nest("", &S::seeding, seedingTable());
  }();
  return table;
}

SeedDrillSettings::SeedDrillSettings() { table().applyDefaults(*this); }

const ParamTable<StateEstimatorSettings>& StateEstimatorSettings::table() {
  using S = StateEstimatorSettings;
  static const ParamTable<S> table({
      text("fix_source", &S::fix_source, "",
           "lockstep only: the node (relative name) whose sensors/fix keys (rate, dropout) say when the plant "
           "measures a fix; each step then waits for the fixes it is due to apply, so a run does not depend on "
           "which connection delivers first (sim.launch: plant_sim). \"\": apply the fixes that have come"),
  });
  return table;
}

StateEstimatorSettings::StateEstimatorSettings() { table().applyDefaults(*this); }

const ParamTable<RunMonitorSettings>& RunMonitorSettings::table() {
  using S = RunMonitorSettings;
  static const ParamTable<S> table({
      text("label", &S::label, "run", "column heading of the metric table"),
      text("output", &S::output, "", "metrics YAML written at the end (\"\" = none)"),
      flag("time_domain", &S::time_domain, true,
           "rise, settling and overshoot too (keeps every sample: ~115 MB per hour at 1 kHz); false: integrals "
           "only, constant memory"),
      flag("exit_at_end", &S::exit_at_end, false, "end the launch when the metrics are printed (headless)"),
      text("recorder", &S::recorder, "",
           "the recorder's recorded_until topic: the end waits until it has the last period (\"\" = no recorder)"),
      number("recorder_timeout", &S::recorder_timeout, 60.0, Limits::positive(), "s",
             "longest wait for the recorder at the end (wall time); then FATAL and exit 3"),
  });
  return table;
}

RunMonitorSettings::RunMonitorSettings() { table().applyDefaults(*this); }

const ParamTable<FleetMonitorSettings>& FleetMonitorSettings::table() {
  using S = FleetMonitorSettings;
  static const ParamTable<S> table({
      integer("robots", &S::robots, 2, Limits::closed(2, 64), "",
              "robots in the fleet: robot_0 ... robot_<robots-1>, each with its own clock and ground_truth"),
      number("safety_distance", &S::safety_distance, 0.8, Limits::positive(), "m",
             "two robots' axle midpoints closer than this at one stamp: an encounter, warned about and counted"),
      flag("exit_at_end", &S::exit_at_end, false,
           "end the launch once every robot's clock has reached run/duration and its run_monitor has printed "
           "(headless)"),
      flag("yield", &S::yield, false,
           "a fleet sharing a field (fleet.launch field_file:=): on every decision stamp, once every robot's "
           "fleet/status for it is in, decide who holds (core/simulation/fleet_yield.h: the later robot of a pair "
           "within yield_distance) and publish the verdict on /fleet/verdict; the robots' references wait for it "
           "(reference_generator fleet/yield)"),
      number("yield_distance", &S::yield_distance, 3.0, Limits::positive(), "m",
             "a robot holds while one of higher priority is closer than this (more than safety_distance: a held "
             "robot slows to a stop over reference_generator's fleet/ramp_time)"),
      number("yield_hysteresis", &S::yield_hysteresis, 0.5, Limits::nonNegative(), "m",
             "a held robot goes on once every robot of higher priority is farther than yield_distance + this"),
      number("decision_period", &S::decision_period, 0.1, Limits::closed(1e-3, 10.0), "s",
             "simulated time between verdicts (the robots' fleet/decision_period must be the same)"),
  });
  return table;
}

FleetMonitorSettings::FleetMonitorSettings() { table().applyDefaults(*this); }

const ParamTable<PsoTunerSettings>& PsoTunerSettings::table() {
  using S = PsoTunerSettings;
  static const ParamTable<S> table({
      integer("particles", &S::particles, 20, Limits::atLeast(1), "", "swarm size (Table 5.4)"),
      integer("iterations", &S::iterations, 30, Limits::atLeast(0), "",
              "update + evaluate rounds after the initial swarm (Table 5.4)"),
      integer("seed", &S::seed, 1, Limits::atLeast(0), "",
              "random seed; the same seed gives the same result for any "
              "thread count"),
      integer("threads", &S::threads, 0, Limits::atLeast(0), "", "evaluation threads; 0 = all cores"),
      number("velocity_clamp", &S::velocity_clamp, 0.2, Limits::closed(0.0, 10.0), "",
             "|v_d| <= this x (upper_d - lower_d); 0 = no clamp"),
      number("w_max", &S::w_max, 0.9, Limits::nonNegative(), "",
             "inertia weight at the first iteration, eq 4.26 (>= w_min)"),
      number("w_min", &S::w_min, 0.1, Limits::nonNegative(), "", "inertia weight at the last iteration"),
      number("c1", &S::c1, 2.0, Limits::nonNegative(), "", "cognitive acceleration, eq 4.27"),
      number("c2", &S::c2, 2.0, Limits::nonNegative(), "", "social acceleration"),
      choice("mode", &S::adaptive, true, {{"atsmc", true}, {"tsmc", false}}, "controller tuned"),
      text("controller", &S::controller, "",
           "pair tuned, outer+inner (kanayama|pure_pursuit|rpp + atsmc|tsmc|pid); \"\" = kanayama + mode"),
      number("duration", &S::duration, 25.0, Limits::closed(1e-3, 1e5), "s", "simulated length of one evaluation"),
      number("control_rate", &S::control_rate, 1000.0, Limits::closed(1.0, 100000.0), "Hz",
             "plant step and control rate of the evaluations"),
      text("cost", &S::cost, "itae", "tracking index summed over x, y, theta", {"itae", "ise", "iae", "itse"}),
      number("torque_weight", &S::torque_weight, 0.0, Limits::nonNegative(), "1/(N^2 m^2 s)",
             "weight of int (tau_R^2 + tau_L^2) dt; 0 = off"),
      number("chattering_weight", &S::chattering_weight, 0.0, Limits::nonNegative(), "1/(N m)",
             "weight of sum_k (|dtau_R| + |dtau_L|) over control periods; 0 = off"),
      text("output", &S::output, "", "gains YAML written at the end (\"\" = $ROS_HOME or ~/.ros/tuned_gains.yaml)"),
  });
  return table;
}

PsoTunerSettings::PsoTunerSettings() { table().applyDefaults(*this); }

std::string PsoTunerSettings::validate() const {
  const std::string e = table().checkRanges(*this);
  if (!e.empty()) return e;
  if (w_max < w_min) return "w_max = " + formatValue(w_max) + " must be >= w_min = " + formatValue(w_min);
  return "";
}

}  // namespace core
}  // namespace sowing_robot
