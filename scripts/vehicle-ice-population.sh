#!/usr/bin/env bash
# The ice population of docs/vehicle.md ("What is left", item 6): 16 straight ice stops drawn
# from the tuning set's two ice scenarios (tuning/t_ice_80.yaml on `ice`, tuning/t_ice_b_120.yaml
# on `ice_b`), at 60-130 km/h, seeds 3001-3016; only name, seed and initial speed change. Tuning
# scenarios only: never a reported figure's source. Usage: scripts/vehicle-ice-population.sh [OUT_DIR]
# A second population (docs/vehicle.md, "What is left" item 6): ICE_POP_SEED_BASE=3100
# ICE_POP_SPEED_OFFSET=5 (seeds 3101-3116 at 65-135 km/h).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="${1:-/tmp/bbw-ice-population}"
T="$ROOT/config/scenarios/vehicle/tuning"
mkdir -p "$OUT/scenarios"
SEED_BASE="${ICE_POP_SEED_BASE:-3000}"
SPEED_OFFSET="${ICE_POP_SPEED_OFFSET:-0}"
i=0
for base_speed in 60 70 80 90 100 110 120 130; do
  speed=$((base_speed + SPEED_OFFSET))
  for base in t_ice_80 t_ice_b_120; do
    i=$((i + 1))
    # Paths made absolute so the copies run from OUT.
    sed -e "s/^name: .*/name: ip_$i/; s/^seed: .*/seed: $((SEED_BASE + i))/; s/^initial_speed_km_h: .*/initial_speed_km_h: $speed/" \
        -e "s|^corners: \.\./|corners: $ROOT/config/scenarios/vehicle/|; s|^vehicle: \.\./\.\./\.\./|vehicle: $ROOT/config/|" \
        -e "s|^brake_control: \.\./\.\./\.\./|brake_control: $ROOT/config/|" \
        "$T/$base.yaml" > "$OUT/scenarios/ip_$(printf %02d $i).yaml"
  done
done
exec "$ROOT/scripts/vehicle-results.sh" "$OUT/runs" "$OUT/scenarios"
