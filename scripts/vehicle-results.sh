#!/usr/bin/env bash
# Runs every vehicle scenario in process (bbw_vehicle_inproc) and prints the results table of
# docs/vehicle.md from each run's summary.json. Usage: scripts/vehicle-results.sh [OUT_DIR] [SCENARIO_DIR]
# SCENARIO_DIR defaults to the 12 reported scenarios (config/scenarios/vehicle); the tuning set is
# config/scenarios/vehicle/tuning (tune there only: docs/vehicle.md).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BBW_BUILD_DIR:-$ROOT/build}/bin/bbw_vehicle_inproc"
OUT="${1:-/tmp/bbw-vehicle-results}"
DIR="${2:-$ROOT/config/scenarios/vehicle}"
mkdir -p "$OUT"
echo "| scenario | stop (m) | ideal (m) | ratio | epsilon | longest lock above 15 km/h (s) | max yaw rate (deg/s) | max lateral (m) | mean decel (g) | rtf |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for f in "$DIR"/*.yaml; do
  name="$(basename "$f" .yaml)"
  "$BIN" "$f" --out "$OUT/$name" >/dev/null
  python3 - "$OUT/$name/summary.json" "$name" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); v = s["vehicle"]
def f(x, d=3):
    return "-" if x is None else f"{x:.{d}f}"
lock = max(v["longest_wheel_lock_s"].values())
print(f"| {sys.argv[2]} | {f(v['stopping_distance_m'],2)} | {f(v['ideal_stopping_distance_m'],2)} | {f(v['distance_ratio'])} | "
      f"{f(v['adhesion_utilisation'])} | {f(lock)} | {f(v['max_yaw_rate_deg_s'],2)} | {f(v['max_lateral_deviation_m'],2)} | "
      f"{f(v['mean_deceleration_g'])} | {s['real_time_factor']:.0f}x |")
PY
done
