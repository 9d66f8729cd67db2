#!/usr/bin/env bash
# Re-records tests/node/data/lockstep_digests.txt from ./bbw run over Fast DDS (lockstep), and
# checks that the in-process runner (bbw_inproc) writes the same bytes for each scenario.
# Use it only when a change is meant to change the logs, and say why in the commit and in
# docs/architecture.md ("Pinned logs").
#   scripts/pin-lockstep-digests.sh [BUILD_DIR]   (default build/)
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${1:-$ROOT/build}"
OUT="$(mktemp -d)"
trap 'rm -rf "$OUT"' EXIT
FILE="$ROOT/tests/node/data/lockstep_digests.txt"
scenarios=$(grep -v '^#' "$FILE" | awk '{print $1}' | sort -u)
new="$OUT/digests.txt"
grep '^#' "$FILE" > "$new"
for s in $scenarios; do
  n=$(basename "$s" .yaml)
  "$BUILD/bin/bbw_launch" "$ROOT/$s" --out "$OUT/dds_$n" --mode lockstep --no-report > "$OUT/$n.log" 2>&1 \
    || { echo "pin: $s: ./bbw run failed (log $OUT/$n.log)" >&2; cat "$OUT/$n.log" >&2; exit 1; }
  files=$(grep -v '^#' "$FILE" | awk -v s="$s" '$1 == s {print $2}')
  inproc_ok=1
  if ! grep -q "type: *\(kill\|restart\)" "$ROOT/$s"; then
    "$BUILD/bin/bbw_inproc" "$ROOT/$s" --out "$OUT/mem_$n" > /dev/null
    for f in $files; do cmp -s "$OUT/dds_$n/$f" "$OUT/mem_$n/$f" || { echo "pin: $s: $f differs between DDS and in-process" >&2; inproc_ok=0; }; done
  fi
  [ $inproc_ok = 1 ] || exit 1
  for f in $files; do echo "$s $f $(sha256sum "$OUT/dds_$n/$f" | cut -d' ' -f1)"; done >> "$new"
  echo "pin: $s: $(echo $files | wc -w) logs"
done
cp "$new" "$FILE"
echo "pin: wrote $FILE"
