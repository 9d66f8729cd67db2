#!/usr/bin/env bash
# "Does calibration matter?" (docs/vehicle.md): the hot-caliper stop with the corners' force
# feedback from (a) the raw load cell, (b) the end-of-line curve only, (c) the paper's calibrator,
# (d) the robust calibrator; prints the table. Usage: scripts/vehicle-calibration-study.sh [SCENARIO] [OUT]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BBW_BUILD_DIR:-$ROOT/build}/bin/bbw_vehicle_inproc"
S="${1:-$ROOT/config/scenarios/vehicle/dry_hot_caliper_FL54C.yaml}"
OUT="${2:-/tmp/bbw-vehicle-calibration}"
mkdir -p "$OUT"
"$BIN" "$S" --out "$OUT/a_load_cell" --no-plots --feedback load_cell >/dev/null
"$BIN" "$S" --out "$OUT/b_eol_curve" --no-plots --feedback eol_curve >/dev/null
"$BIN" "$S" --out "$OUT/c_paper" --no-plots --feedback compensated --calibrator "$ROOT/config/calibrator/paper.yaml" >/dev/null
"$BIN" "$S" --out "$OUT/d_robust" --no-plots --feedback compensated --calibrator "$ROOT/config/calibrator/robust.yaml" >/dev/null
echo "| feedback | stopping distance (m) | clamp-force error FL / FR / RL / RR (%) | front balance FL-FR (%) | max yaw rate (deg/s) | max lateral (m) | driver's max steer (deg) | fits accepted FL/FR/RL/RR |"
echo "|---|---|---|---|---|---|---|---|"
for d in a_load_cell b_eol_curve c_paper d_robust; do
  python3 - "$OUT/$d/summary.json" "$d" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); v = s["vehicle"]; e = s["clamp_force_error"]
err = " / ".join(f"{100*e[c]:+.1f}" for c in ["FL", "FR", "RL", "RR"])
print(f"| {sys.argv[2]} | {v['stopping_distance_m']:.2f} | {err} | {100*v['front_balance_error']:+.2f} | "
      f"{v['max_yaw_rate_deg_s']:.2f} | {v['max_lateral_deviation_m']:.3f} | {v['max_steer_deg']:.3f} | "
      + "/".join(str(s['fits_accepted'][c]) for c in ["FL", "FR", "RL", "RR"]) + " |")
PY
done
