#include "bbw/vehicle_run/vehicle_scenario.hpp"

#include <algorithm>
#include <filesystem>

#include "bbw/brake/brake_yaml.hpp"
#include "bbw/common/strict_yaml.hpp"

namespace bbw::vehicle_run {

using config::Range;
using config::Reader;

namespace {

std::string beside(const std::string& file, const std::string& rel) {
  const std::filesystem::path p(rel);
  if (p.is_absolute()) return rel;
  return (std::filesystem::path(file).parent_path() / p).lexically_normal().string();
}

std::size_t surface_index(Reader& r, const std::string& key, const std::vector<vehicle::Surface>& table) {
  const std::string name = r.string(key);
  for (std::size_t i = 0; i < table.size(); ++i) {
    if (table[i].name == name) return i;
  }
  std::string known;
  for (const auto& s : table) known += (known.empty() ? "" : ", ") + s.name;
  r.fail(key, "unknown surface '" + name + "' (the vehicle file defines: " + known + ")");
}

}  // namespace

bool is_vehicle_scenario(const std::string& file) {
  try {
    Reader r = Reader::from_file(file);
    return r.has("vehicle");
  } catch (const config::ConfigError&) {
    return false;
  }
}

VehicleScenario load_vehicle_scenario(const std::string& file) {
  Reader r = Reader::from_file(file);
  VehicleScenario s;
  s.file = file;
  s.name = r.string("name");
  s.seed = static_cast<std::uint64_t>(r.integer("seed", 0, 1LL << 53));
  const std::string corners = beside(file, r.string("corners"));
  s.corners = faults::load_fault_scenario(corners);
  for (const auto& c : s.corners.scenario.corners) {
    if (c.drive.mode != scenario::DriveMode::Demand) r.fail("corners", corners + ": corner " + c.name + " must be demand-driven");
  }
  if (s.corners.scenario.corners.size() != 4) r.fail("corners", corners + ": a vehicle needs the four corners FL, FR, RL, RR");
  s.corners.scenario.duration_s = r.number("duration_s", Range::closed(0.1, 600));
  s.corners.scenario.duration_line = r.line();
  try {
    faults::check_schedule(s.corners.scenario, s.corners.faults);
  } catch (const config::ConfigError& e) {
    r.fail("duration_s", std::string("the corners' fault schedule does not fit: ") + e.what());
  }
  s.vehicle = vehicle::load_vehicle_config(beside(file, r.string("vehicle")));
  s.brake = brake::load_brake_control(beside(file, r.string("brake_control")));
  s.initial_speed_m_s = r.number("initial_speed_km_h", Range::closed(0, 250)) / 3.6;
  {
    Reader road = r.map("road");
    s.road.surfaces = s.vehicle.vehicle.surfaces;
    s.road.base_surface = surface_index(road, "surface", s.road.surfaces);
    s.road.grade_percent = road.number("grade_percent", Range::closed(-30, 30));
    s.road.ambient_C = road.number("ambient_C", Range::closed(-40, 50));
    for (Reader p : road.maps("patches")) {
      vehicle::Patch patch;
      patch.surface = surface_index(p, "surface", s.road.surfaces);
      patch.x_from_m = p.number("x_from_m");
      patch.x_to_m = p.number("x_to_m");
      patch.y_from_m = p.number_or("y_from_m", -1e6);
      patch.y_to_m = p.number_or("y_to_m", 1e6);
      if (!(patch.x_to_m > patch.x_from_m)) p.fail("x_to_m", "must be > x_from_m");
      if (!(patch.y_to_m > patch.y_from_m)) p.fail("y_to_m", "must be > y_from_m");
      p.finish();
      s.road.patches.push_back(patch);
    }
    road.finish();
  }
  {
    const std::vector<double> flat = r.numbers("pedal_travel");
    if (flat.size() < 2 || flat.size() % 2 != 0) r.fail("pedal_travel", "a flat list of [t_s, fraction] pairs");
    for (std::size_t i = 0; i < flat.size(); i += 2) {
      if (flat[i + 1] < 0.0 || flat[i + 1] > 1.0) r.fail("pedal_travel", "travel fractions must be in [0, 1]");
      if (i > 0 && !(flat[i] > flat[i - 2])) r.fail("pedal_travel", "times must increase");
      s.pedal.emplace_back(flat[i], flat[i + 1]);
    }
  }
  if (auto d = r.optional_map("driver")) {
    s.driver = true;
    s.driver_params.path_radius_m = d->number("path_radius_m");
    s.driver_params.preview_s = d->number("preview_s", Range::non_negative());
    s.driver_params.gain_rad_per_m = d->number("gain_rad_per_m", Range::non_negative());
    s.driver_params.yaw_rate_gain_s = d->number("yaw_rate_gain_s", Range::closed(0, 2));
    s.driver_params.reaction_s = d->number("reaction_s", Range::closed(0, 0.5));
    s.driver_params.lag_s = d->number("lag_s", Range::positive());
    s.driver_params.max_rate_rad_s = d->number("max_rate_rad_s", Range::positive());
    s.driver_params.max_steer_rad = d->number("max_steer_rad", Range{0.0, 0.7, true, true});
    d->finish();
    try {
      s.driver_params.validate();
    } catch (const std::invalid_argument& e) {
      d->fail("", e.what());
    }
  }
  if (auto c = r.optional_map("cruise")) {
    s.cruise_until_s = c->number("until_s", Range::closed(0, s.corners.scenario.duration_s));
    s.cruise_gain_Nm_per_m_s = c->number("gain_Nm_per_m_s", Range::closed(0, 1e5));
    c->finish();
  }
  {
    const std::vector<double> disc = r.numbers("disc_temperature_C", Range::closed(-40, 800));
    if (disc.size() != 4) r.fail("disc_temperature_C", "four values: FL, FR, RL, RR");
    std::copy(disc.begin(), disc.end(), s.disc_C.begin());
  }
  for (std::size_t i = 0; i < 4; ++i) s.caliper_C[i] = s.corners.scenario.corners[i].conditions.temperature_C;
  {
    s.processes = r.strings("processes");
    const std::vector<std::string> need{"ccu", "FL", "FR", "RL", "RR", "vehicle", "pedal"};
    for (const auto& p : s.processes) {
      if (std::find(need.begin(), need.end(), p) == need.end()) r.fail("processes", "unknown process '" + p + "'");
    }
    for (const auto& p : need) {
      if (std::find(s.processes.begin(), s.processes.end(), p) == s.processes.end()) {
        r.fail("processes", "a vehicle scenario runs " + p + " too");
      }
    }
  }
  r.finish();
  return s;
}

}  // namespace bbw::vehicle_run
