// The `vehicle` object of summary.json (docs/vehicle.md): stopping distance against the physical
// limit of the tyre model, UN R13-H Annex 6 adhesion utilisation, wheel lock, slip, yaw and
// lateral deviation, mean deceleration.
#pragma once

#include <array>
#include <string>

#include "bbw/common/json.hpp"
#include "bbw/vehicle_run/vehicle_run.hpp"

namespace bbw::vehicle_run {

struct VehicleMetrics {
  bool stopped = false;
  double onset_speed_m_s = 0.0;
  double stopping_distance_m = 0.0;       // from the pedal's first travel to standstill
  double stopping_time_s = 0.0;
  double mu_peak = 0.0;                   // the tyre model's peak at the start surface, with load transfer
  double ideal_stopping_distance_m = 0.0; // v^2 / (2 mu_peak g)
  double distance_ratio = 0.0;
  // UN R13-H Annex 6 Appendix 2: z_AL = 0.849 / t(45 -> 15 km/h) measured in this run (which starts
  // at its own speed, not 55 km/h); k_M = (k_f F_f,dyn + k_r F_r,dyn) / (P g) with k_f, k_r from
  // simulated braking runs per axle without anti-lock (axle_adhesion); epsilon = z_AL / k_M. NaN
  // when the run did not pass 45 and 15 km/h or the road is not uniform.
  double z_AL = 0.0;
  double k_M = 0.0;
  double adhesion_utilisation = 0.0;
  std::array<double, 4> wheel_lock_s{};
  std::array<double, 4> longest_wheel_lock_s{};
  std::array<double, 4> slip_rms{};       // while braking above 15 km/h
  double max_yaw_rate_deg_s = 0.0;
  double max_lateral_deviation_m = 0.0;   // from the driver's path (straight: |y|)
  double mean_deceleration_g = 0.0;       // onset speed / stopping time / g
  // During the stop above 15 km/h with both front calipers above 1 kN: the mean of
  // (F_FL - F_FR) / mean(F_FL, F_FR) of the true clamp forces (brake balance across the axle).
  double front_balance_error = 0.0;
  double max_steer_deg = 0.0;             // the driver's largest road-wheel angle during the stop
};

// The CCU's commands against the calipers' true forces (in process: the trace holds both): per
// corner the mean of (F_true - F_cmd) / F_cmd during the stop above 15 km/h where F_cmd > 1 kN.
std::array<double, 4> clamp_force_error(const VehicleRun& run);

VehicleMetrics vehicle_metrics(const VehicleScenario& s, const VehicleNode& vehicle);
inline VehicleMetrics vehicle_metrics(const VehicleScenario& s, const VehicleRun& run) { return vehicle_metrics(s, run.vehicle_node()); }
void write_vehicle_json(json::Writer& w, const VehicleMetrics& m);
// The vehicle process's and the in-process run's common outputs: the truth per CCU period
// (vehicle_truth.csv: the same bytes from both, test SystemVehicleRun.*) and the metrics as a
// JSON document {"vehicle": {...}} (vehicle.json, merged into summary.json by bbw_launch).
void write_truth_csv(const std::string& file, const std::vector<TruthRow>& truth);
void write_vehicle_file(const std::string& file, const VehicleMetrics& m);
// The run's plots from DIR/vehicle_truth.csv through gnuplot: DIR/speeds.png (vehicle and wheel
// speeds), slips.png, clamp_forces.png (true), mu_used.png, path.png (x-y). Throws
// std::runtime_error when gnuplot fails (bbw/common/plot.hpp).
void write_vehicle_plots(const std::string& dir, const std::string& title);
// The tyre model's peak adhesion for a straight stop on `surface` (deceleration z at which every
// wheel is at its peak at its dynamic load), and the per-axle adhesion k at deceleration z.
double peak_adhesion(const vehicle::VehicleParams& p, const vehicle::Surface& surface);
// The regulation's adhesion coefficients of the front and the rear axle (Annex 6 Appendix 2,
// 1.1): runs from 50 km/h with one axle braked at a constant clamp force in 0.25 kN increments
// (the plant alone: no anti-lock, no e-caliper dynamics), z = 0.566 / t(40 -> 20 km/h) from the
// mean of the three shortest times without wheel lock within 1.05 t_min, less the unbraked axle's
// rolling resistance (0.015 driven, 0.010 not), over the braked axle's dynamic load.
struct AxleAdhesion {
  double front = 0.0;     // k_f
  double rear = 0.0;      // k_r
  double z_front = 0.0;   // the braking rates they come from
  double z_rear = 0.0;
};
AxleAdhesion axle_adhesion(const vehicle::VehicleParams& p, const vehicle::RoadParams& road);

}  // namespace bbw::vehicle_run
