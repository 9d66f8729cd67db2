#!/usr/bin/env bash
# The CCU's clamp-force estimate against the truth on a campaign's runs (docs/calibrator.md,
# "Starting from the caliper's end-of-line test"): runs bbw_inproc on the first N runs' scenarios
# and writes, per corner, whether its calibrator ever had a fit accepted and its RMS and worst
# |estimate - clamp force| from 1 s on (samples whose estimate is invalid are counted, not scored),
# then the median, p90 and worst over the corners no fault was injected on.
#   scripts/estimate-accuracy.sh BUILD_DIR CAMPAIGN_RUNS_DIR N OUT.txt [bbw_inproc options...]
# e.g. scripts/estimate-accuracy.sh build out/campaign_stiff10_ff/runs 25 out/accuracy_stiff10_ff.txt
# OUT.txt: run corner fitted(0/1) faulted(0/1) rms_kN worst_kN invalid_samples
set -euo pipefail
if [ $# -lt 4 ]; then
  sed -n '2,9p' "$0" >&2
  exit 2
fi
build=$1 runs=$2 n=$3 out=$4
shift 4
[ -x "$build/bin/bbw_inproc" ] || { echo "estimate-accuracy: no $build/bin/bbw_inproc" >&2; exit 2; }
[ -d "$runs" ] || { echo "estimate-accuracy: no runs directory $runs" >&2; exit 2; }
[[ "$n" =~ ^[1-9][0-9]*$ ]] || { echo "estimate-accuracy: N must be a positive integer, got '$n'" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
: > "$out"
mapfile -t list < <(ls "$runs" | head -n "$n")
[ ${#list[@]} -gt 0 ] || { echo "estimate-accuracy: $runs holds no runs" >&2; exit 2; }
k=0
for r in "${list[@]}"; do
  k=$((k + 1))
  scen="$runs/$r/scenario.yaml"
  [ -f "$scen" ] || { echo "estimate-accuracy: $scen missing" >&2; exit 1; }
  rm -rf "$tmp/run"
  "$build/bin/bbw_inproc" "$scen" --out "$tmp/run" "$@" > "$tmp/log" 2>&1 \
    || { echo "estimate-accuracy: bbw_inproc failed on $scen:" >&2; cat "$tmp/log" >&2; exit 1; }
  faulted=$(grep -o "corner: [A-Z][A-Z]" "$scen" | awk '{print $2}' | sort -u | tr '\n' ' ' || true)
  for c in FL FR RL RR; do
    [ -f "$tmp/run/ccu_$c.csv" ] || continue
    awk -F, -v run="$r" -v c="$c" -v fl="$faulted" '
      NR > 1 && $1 > 1.0 {
        if ($13 ~ /n/) { invalid++; next }
        e = $13 - $8; n++; s += e * e; if (e < 0) e = -e; if (e > m) m = e; if ($18 == 1) f = 1
      }
      END { printf "%s %s %d %d %.4f %.3f %d\n", run, c, f, index(fl, c) ? 1 : 0, n ? sqrt(s / n) : -1, m, invalid }' \
      "$tmp/run/ccu_$c.csv" >> "$out"
  done
  echo "estimate-accuracy: $k/${#list[@]} runs" >&2
done
sort -k5 -g "$out" | awk '$4 == 0 && $5 >= 0 {rms[++n] = $5; if ($6 > w) {w = $6}; fit += $3; last = $1 " " $2}
  END {
    if (n == 0) { print "estimate-accuracy: no corner without a fault to score" > "/dev/stderr"; exit 1 }
    printf "%d corners without a fault, %d fitted; RMS |estimate - clamp force| median %.3f, p90 %.3f, worst %.3f kN (%s); worst |error| %.2f kN\n",
      n, fit, rms[int((n + 1) / 2)], rms[int(0.9 * n + 0.999)], rms[n], last, w
  }'
