#!/usr/bin/env bash
# ./bbw campaign SPEC.yaml --out DIR [--jobs N] [--transport dds|memory] [--keep-logs]
#                [--sshlogin LOGIN]... [--ssh CMD]
# A randomised fault campaign (docs/faults.md, "Campaigns"): bbw_campaign draws the runs, GNU
# parallel carries them out (each over Fast DDS on its own free domain, or in memory), and
# bbw_campaign writes campaign.json and report.html. A killed campaign resumes: the same command
# again skips every run with a result. --sshlogin (repeatable) spreads the runs over hosts that
# see DIR and the build at the same paths (a shared file system); ':' is this host. --ssh replaces
# ssh (e.g. scripts/netns-ssh.sh, network namespaces as hosts).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BBW_BUILD_DIR:-$ROOT/build}/bin"

die() { echo "bbw campaign: $*" >&2; exit 2; }

spec="" out="" jobs="$(nproc 2>/dev/null || echo 2)" transport=dds keep=() logins=() ssh_cmd=()
while [ $# -gt 0 ]; do
  case "$1" in
    --out) [ $# -ge 2 ] || die "--out needs a directory"; out="$2"; shift 2 ;;
    --jobs) [ $# -ge 2 ] || die "--jobs needs a number"; jobs="$2"; shift 2
            [[ "$jobs" =~ ^[1-9][0-9]*$ ]] || die "--jobs must be a positive integer, got '$jobs'" ;;
    --transport) [ $# -ge 2 ] || die "--transport needs dds or memory"; transport="$2"; shift 2
                 [ "$transport" = dds ] || [ "$transport" = memory ] || die "--transport must be dds or memory, got '$transport'" ;;
    --keep-logs) keep=(--keep-logs); shift ;;
    --sshlogin) [ $# -ge 2 ] || die "--sshlogin needs a login"; logins+=(--sshlogin "$2"); shift 2 ;;
    --ssh) [ $# -ge 2 ] || die "--ssh needs a command"; ssh_cmd=(--ssh "$2"); shift 2 ;;
    -h|--help) sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) die "unknown argument '$1'" ;;
    *) [ -z "$spec" ] || die "one spec only, got '$1' too"; spec="$1"; shift ;;
  esac
done
[ -n "$spec" ] || die "a campaign spec (config/campaigns/*.yaml) is required"
[ -n "$out" ] || die "--out DIR is required"
command -v parallel >/dev/null 2>&1 || die "GNU parallel is missing (Debian package 'parallel'): run ./bbw setup"
[ -x "$BIN/bbw_campaign" ] || die "$BIN/bbw_campaign is missing: run ./bbw build"

"$BIN/bbw_campaign" plan "$spec" --out "$out"
out_abs="$(cd "$out" && pwd)"
if [ -s "$out_abs/pending.txt" ]; then
  # A run's own failure is recorded in its result; parallel's status counts jobs that could not
  # score at all, which the report shows as missing runs.
  parallel --will-cite --jobs "$jobs" --line-buffer "${logins[@]}" "${ssh_cmd[@]}" \
    "$BIN/bbw_campaign" run "$out_abs" {} --transport "$transport" "${keep[@]}" :::: "$out_abs/pending.txt" || \
    echo "bbw campaign: $? run(s) ended without a result; rerun the same command to resume" >&2
fi
exec "$BIN/bbw_campaign" report "$out_abs"
