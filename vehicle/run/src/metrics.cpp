#include "bbw/vehicle_run/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <vector>

#include "bbw/common/plot.hpp"
#include "bbw/vehicle/tyre.hpp"

namespace bbw::vehicle_run {

namespace {
constexpr double kG = 9.81;

struct AxleLoads {
  double front_N, rear_N;
};
AxleLoads axle_loads(const vehicle::ChassisParams& c, double z) {
  const double L = c.wheelbase_m();
  const double W = c.mass_kg * kG;
  return {W * (c.cg_to_rear_axle_m + c.cg_height_m * z) / L, W * (c.cg_to_front_axle_m - c.cg_height_m * z) / L};
}
double axle_mu(const vehicle::VehicleParams& p, const vehicle::Surface& s, double axle_N) {
  return vehicle::peak_longitudinal_mu(p.tyre, 0.5 * axle_N, s.mu_scale, s.stiffness_scale).mu;
}
}  // namespace

namespace {

// One run of UN R13-H Annex 6 Appendix 2, 1.1: from 50 km/h, a constant clamp force on one axle's
// brakes only (the plant alone, no anti-lock, no e-caliper dynamics); the time from 40 to 20 km/h,
// and whether a braked wheel locked (below half the vehicle speed) above 20 km/h.
struct AxleRun {
  double t_s = 0.0;
  bool locked = false;
  bool valid = false;
};
// `give_up_s`: a run still above 20 km/h this long after 40 km/h, or above 40 km/h this long
// after the start, is cut short (invalid): its time cannot count. A run ends at its first lock too
// (a locked run never counts).
AxleRun axle_run(const vehicle::VehicleParams& p, const vehicle::RoadParams& road, bool front, double clamp_kN,
                 double give_up_s) {
  vehicle::Vehicle v(p, road);
  v.reset(50.0 / 3.6, {40, 40, 40, 40}, {28, 28, 28, 28});
  vehicle::VehicleInputs in;
  const std::size_t a = front ? 0 : 2;
  in.clamp_force_kN[a] = in.clamp_force_kN[a + 1] = clamp_kN;
  AxleRun r;
  double t40 = -1.0;
  double prev_v = v.speed_m_s(), prev_t = 0.0;
  while (v.state().time_s < 30.0 && !v.state().stopped) {
    v.step(0.001, in);
    const double speed = v.speed_m_s(), t = v.state().time_s;
    if (speed > 20.0 / 3.6) {
      for (std::size_t w = a; w < a + 2; ++w) {
        if (v.state().wheels[w].spin_rad_s * p.chassis.wheel_radius_m < 0.5 * speed) r.locked = true;
      }
      if (r.locked) break;
    }
    auto cross = [&](double kmh) {
      const double x = kmh / 3.6;
      return prev_v > x && speed <= x ? prev_t + (prev_v - x) / (prev_v - speed) * (t - prev_t) : -1.0;
    };
    if (t40 < 0.0) t40 = cross(40.0);
    const double t20 = cross(20.0);
    if (t40 >= 0.0 && t20 >= 0.0) {
      r.t_s = t20 - t40;
      r.valid = true;
      break;
    }
    // Cut short: its 20 km/h comes later still; or, before 40 km/h, the first 10 km/h took longer
    // than the next 20 may (a constant force's deceleration only falls with the drag).
    if (t40 >= 0.0 ? t - t40 > give_up_s : t > give_up_s) break;
    prev_v = speed;
    prev_t = t;
  }
  return r;
}

}  // namespace

AxleAdhesion axle_adhesion(const vehicle::VehicleParams& p, const vehicle::RoadParams& road) {
  const vehicle::ChassisParams& c = p.chassis;
  const double P = c.mass_kg, E = c.wheelbase_m(), h = c.cg_height_m;
  const double Ff = P * kG * c.cg_to_rear_axle_m / E, Fr = P * kG * c.cg_to_front_axle_m / E;
  AxleAdhesion out;
  for (const bool front : {true, false}) {
    // Increments of the input force; the shortest times without lock (1.1.3). From the largest
    // force down (the same forces as counting up: multiples of 0.25 are exact): a locked run ends
    // at its lock, and once a time t is known a run 1.05 t after its 40 km/h is cut short, since
    // only times within 1.05 of the shortest count. The times that count are the same, computed
    // in about a fifth of the plant steps (docs/benchmarks.md).
    std::vector<double> times;
    const auto increments = static_cast<int>(std::floor(p.brake(front ? 0 : 2).max_clamp_force_kN / 0.25 + 1e-9));
    double shortest_s = 30.0;
    for (int i = increments; i >= 1; --i) {
      const AxleRun r = axle_run(p, road, front, 0.25 * i, 1.05 * shortest_s);
      if (r.valid && !r.locked) {
        times.push_back(r.t_s);
        shortest_s = std::min(shortest_s, r.t_s);
      }
    }
    if (times.empty()) {
      const double nan = std::numeric_limits<double>::quiet_NaN();
      return {nan, nan, nan, nan};
    }
    std::sort(times.begin(), times.end());
    // 1.1.3.2: the mean of three times within t_min and 1.05 t_min (t_min alone if fewer).
    double sum = 0.0;
    int n = 0;
    for (double t : times) {
      if (t > 1.05 * times.front() || n == 3) break;
      sum += t;
      ++n;
    }
    const double z = 0.566 / (n == 3 ? sum / 3.0 : times.front());
    // 1.1.4-1.1.5: the rolling resistance of the unbraked axle (0.015 driven, the rear here;
    // 0.010 not driven) and the braked axle's dynamic load.
    if (front) {
      out.front = (z * P * kG - 0.015 * Fr) / (Ff + h / E * z * P * kG);
      out.z_front = z;
    } else {
      out.rear = (z * P * kG - 0.010 * Ff) / (Fr - h / E * z * P * kG);
      out.z_rear = z;
    }
  }
  return out;
}

double peak_adhesion(const vehicle::VehicleParams& p, const vehicle::Surface& surface) {
  double z = axle_mu(p, surface, 0.5 * p.chassis.mass_kg * kG);
  for (int i = 0; i < 50; ++i) {
    const AxleLoads a = axle_loads(p.chassis, z);
    z = (axle_mu(p, surface, a.front_N) * a.front_N + axle_mu(p, surface, a.rear_N) * a.rear_N) / (p.chassis.mass_kg * kG);
  }
  return z;
}

VehicleMetrics vehicle_metrics(const VehicleScenario& s, const VehicleNode& run) {
  VehicleMetrics m;
  const vehicle::VehicleParams& p = s.vehicle.vehicle;
  const auto& tr = run.truth();
  m.stopped = run.stop_time_s() >= 0.0;
  m.onset_speed_m_s = run.onset_speed_m_s();
  const double end_path = tr.empty() ? 0.0 : tr.back().path_m;
  m.stopping_distance_m = end_path - run.onset_path_m();
  m.stopping_time_s = m.stopped ? run.stop_time_s() - run.brake_onset_s() : std::numeric_limits<double>::quiet_NaN();
  const vehicle::Surface& start_surface = s.road.surface_at(0.0, 0.0);
  m.mu_peak = peak_adhesion(p, start_surface);
  m.ideal_stopping_distance_m = m.onset_speed_m_s * m.onset_speed_m_s / (2.0 * m.mu_peak * kG);
  m.distance_ratio = m.stopped ? m.stopping_distance_m / m.ideal_stopping_distance_m : std::numeric_limits<double>::quiet_NaN();
  // z_AL from the time between 45 and 15 km/h (interpolated between periods).
  double t45 = -1.0, t15 = -1.0;
  for (std::size_t i = 1; i < tr.size(); ++i) {
    auto cross = [&](double v_kmh, double& t) {
      const double v = v_kmh / 3.6;
      if (t < 0.0 && tr[i - 1].speed_m_s > v && tr[i].speed_m_s <= v) {
        const double f = (tr[i - 1].speed_m_s - v) / (tr[i - 1].speed_m_s - tr[i].speed_m_s);
        t = tr[i - 1].time_s + f * (tr[i].time_s - tr[i - 1].time_s);
      }
    };
    cross(45.0, t45);
    cross(15.0, t15);
  }
  const bool uniform = s.road.patches.empty();
  if (!uniform) {
    // Not defined on split or jumping surfaces: no single mu_peak.
    m.ideal_stopping_distance_m = m.distance_ratio = std::numeric_limits<double>::quiet_NaN();
  }
  if (uniform && t45 >= 0.0 && t15 > t45) {
    m.z_AL = 0.849 / (t15 - t45);
    const AxleLoads dyn = axle_loads(p.chassis, m.z_AL);
    // k_f, k_r the regulation's way: braking runs with one axle braked, no anti-lock.
    const AxleAdhesion k = axle_adhesion(p, s.road);
    const double k_f = k.front, k_r = k.rear;
    m.k_M = (k_f * dyn.front_N + k_r * dyn.rear_N) / (p.chassis.mass_kg * kG);
    m.adhesion_utilisation = m.z_AL / m.k_M;
  } else {
    m.z_AL = m.k_M = m.adhesion_utilisation = std::numeric_limits<double>::quiet_NaN();
  }
  m.wheel_lock_s = run.wheel_lock_s();
  m.longest_wheel_lock_s = run.longest_lock_s();
  std::array<double, 4> sum{};
  std::size_t count = 0;
  for (const TruthRow& t : tr) {
    m.max_yaw_rate_deg_s = std::max(m.max_yaw_rate_deg_s, std::abs(t.yaw_rate_rad_s) * 180.0 / M_PI);
    const double dev = std::abs(vehicle::path_error(s.driver ? s.driver_params.path_radius_m : 0.0, t.x_m, t.y_m, t.yaw_rad).lateral_m);
    m.max_lateral_deviation_m = std::max(m.max_lateral_deviation_m, dev);
    if (t.braking && t.speed_m_s > 15.0 / 3.6) {
      for (std::size_t w = 0; w < 4; ++w) sum[w] += t.slip[w] * t.slip[w];
      ++count;
    }
  }
  for (std::size_t w = 0; w < 4; ++w) m.slip_rms[w] = count ? std::sqrt(sum[w] / count) : 0.0;
  double bal = 0.0;
  std::size_t nbal = 0;
  for (const TruthRow& t : tr) {
    if (t.time_s < run.brake_onset_s() || run.brake_onset_s() < 0.0 || t.stopped) continue;
    m.max_steer_deg = std::max(m.max_steer_deg, std::abs(t.steer_rad) * 180.0 / M_PI);
    const double fl = t.clamp_true_kN[0], fr = t.clamp_true_kN[1];
    if (t.speed_m_s > 15.0 / 3.6 && fl > 1.0 && fr > 1.0) {
      bal += (fl - fr) / (0.5 * (fl + fr));
      ++nbal;
    }
  }
  m.front_balance_error = nbal ? bal / static_cast<double>(nbal) : std::numeric_limits<double>::quiet_NaN();
  m.mean_deceleration_g = m.stopped ? m.onset_speed_m_s / m.stopping_time_s / kG : std::numeric_limits<double>::quiet_NaN();
  return m;
}

void write_vehicle_json(json::Writer& w, const VehicleMetrics& m) {
  static const char* names[4] = {"FL", "FR", "RL", "RR"};
  w.begin_object("vehicle");
  w.value("stopped", m.stopped);
  w.value("onset_speed_km_h", m.onset_speed_m_s * 3.6);
  w.value("stopping_distance_m", m.stopping_distance_m);
  w.value("stopping_time_s", m.stopping_time_s);
  w.value("mu_peak", m.mu_peak);
  w.value("ideal_stopping_distance_m", m.ideal_stopping_distance_m);
  w.value("distance_ratio", m.distance_ratio);
  w.value("z_AL", m.z_AL);
  w.value("k_M", m.k_M);
  w.value("adhesion_utilisation", m.adhesion_utilisation);
  w.begin_object("wheel_lock_s");
  for (std::size_t i = 0; i < 4; ++i) w.value(names[i], m.wheel_lock_s[i]);
  w.end_object();
  w.begin_object("longest_wheel_lock_s");
  for (std::size_t i = 0; i < 4; ++i) w.value(names[i], m.longest_wheel_lock_s[i]);
  w.end_object();
  w.begin_object("slip_rms");
  for (std::size_t i = 0; i < 4; ++i) w.value(names[i], m.slip_rms[i]);
  w.end_object();
  w.value("max_yaw_rate_deg_s", m.max_yaw_rate_deg_s);
  w.value("max_lateral_deviation_m", m.max_lateral_deviation_m);
  w.value("mean_deceleration_g", m.mean_deceleration_g);
  w.value("front_balance_error", m.front_balance_error);
  w.value("max_steer_deg", m.max_steer_deg);
  w.end_object();
}

std::array<double, 4> clamp_force_error(const VehicleRun& run) {
  std::array<double, 4> sum{}, n{};
  for (const PeriodTrace& t : run.trace()) {
    if (t.time_s < run.brake_onset_s() || run.brake_onset_s() < 0.0 || t.stopped || t.speed_m_s < 15.0 / 3.6) continue;
    for (std::size_t w = 0; w < 4; ++w) {
      if (t.command_kN[w] <= 1.0) continue;
      sum[w] += (t.clamp_true_kN[w] - t.command_kN[w]) / t.command_kN[w];
      n[w] += 1.0;
    }
  }
  std::array<double, 4> out{};
  for (std::size_t w = 0; w < 4; ++w) out[w] = n[w] > 0 ? sum[w] / n[w] : std::numeric_limits<double>::quiet_NaN();
  return out;
}

void write_truth_csv(const std::string& file, const std::vector<TruthRow>& truth) {
  std::ofstream f(file);
  if (!f) throw std::runtime_error(file + ": cannot write");
  f << "time_s,speed_m_s,x_m,y_m,yaw_rad,yaw_rate_rad_s,ax_m_s2,path_m,steer_rad,stopped";
  static const char* names[4] = {"FL", "FR", "RL", "RR"};
  for (const char* c : names) {
    f << ",wheel_speed_" << c << "_m_s,slip_" << c << ",mu_used_" << c << ",clamp_true_" << c << "_kN,brake_torque_" << c
      << "_Nm,disc_" << c << "_C,caliper_" << c << "_C";
  }
  f << "\n";
  char buf[64];
  auto num = [&](double v) {
    std::snprintf(buf, sizeof buf, ",%.17g", v);
    f << buf;
  };
  for (const TruthRow& t : truth) {
    std::snprintf(buf, sizeof buf, "%.17g", t.time_s);
    f << buf;
    for (double v : {t.speed_m_s, t.x_m, t.y_m, t.yaw_rad, t.yaw_rate_rad_s, t.ax_m_s2, t.path_m, t.steer_rad}) num(v);
    f << (t.stopped ? ",1" : ",0");
    for (std::size_t w = 0; w < 4; ++w) {
      for (double v : {t.wheel_speed_m_s[w], t.slip[w], t.mu_used[w], t.clamp_true_kN[w], t.brake_torque_Nm[w], t.disc_C[w],
                       t.caliper_C[w]}) {
        num(v);
      }
    }
    f << "\n";
  }
  if (!f) throw std::runtime_error(file + ": write failed");
}

void write_vehicle_file(const std::string& file, const VehicleMetrics& m) {
  json::Writer w;
  w.begin_object();
  write_vehicle_json(w, m);
  w.end_object();
  w.save(file);
}

void write_vehicle_plots(const std::string& dir, const std::string& title) {
  using plot::quote;
  const std::string csv = quote(dir + "/vehicle_truth.csv");
  // Columns: 1 time, 2 speed, 3 x, 4 y; per wheel w (0 FL .. 3 RR) from 11 + 7 w: wheel speed,
  // slip, mu used, clamp force, brake torque, disc, caliper.
  auto col = [](int w, int k) { return std::to_string(11 + 7 * w + k); };
  static const char* names[4] = {"FL", "FR", "RL", "RR"};
  // The four wheels' column k; the first names the file unless `more` (a plot that began already).
  auto per_wheel = [&](int k, bool more = false) {
    std::string s;
    for (int w = 0; w < 4; ++w) {
      const bool first = w == 0 && !more;
      s += std::string(first ? "" : ", ") + (first ? csv : std::string("''")) + " using 1:" + col(w, k) +
           " with lines title '" + names[w] + "'";
    }
    return s;
  };
  std::string g = "set terminal pngcairo noenhanced size 1000,600\nset datafile separator ','\nset grid\nset key outside right\n"
                  "set xlabel 'time (s)'\n";
  g += "set output " + quote(dir + "/speeds.png") + "\nset title '" + title + ": vehicle and wheel speeds'\nset ylabel 'm/s'\n";
  g += "plot " + csv + " using 1:2 with lines lw 2 title 'vehicle'" + per_wheel(0, true) + "\n";
  g += "set output " + quote(dir + "/slips.png") + "\nset title '" + title + ": longitudinal slip'\nset ylabel 'slip'\n";
  g += "plot " + per_wheel(1) + "\n";
  g += "set output " + quote(dir + "/clamp_forces.png") + "\nset title '" + title + ": true clamp forces'\nset ylabel 'kN'\n";
  g += "plot " + per_wheel(3) + "\n";
  g += "set output " + quote(dir + "/mu_used.png") + "\nset title '" + title + ": mu used |F| / Fz'\nset ylabel 'mu'\n";
  g += "plot " + per_wheel(2) + "\n";
  g += "set output " + quote(dir + "/path.png") + "\nset title '" + title + ": path (y scale enlarged)'\nset xlabel 'x (m)'\nset ylabel 'y (m)'\n"
       "plot " + csv + " using 3:4 with lines lw 2 title 'CG'\n";
  plot::run_gnuplot(g, dir + "/vehicle_plots.gp");
}

}  // namespace bbw::vehicle_run
