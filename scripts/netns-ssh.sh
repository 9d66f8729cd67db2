#!/usr/bin/env bash
# An `ssh` for GNU parallel whose hosts are Linux network namespaces on this machine (root):
#   ./bbw campaign SPEC --out DIR --ssh scripts/netns-ssh.sh --sshlogin 1/NS_A --sshlogin 1/NS_B
# parallel calls it as `netns-ssh.sh NS -- COMMAND...` (what it would give ssh); the command runs
# in namespace NS through `ip netns exec`, sharing this machine's file system as a shared-file-
# system cluster does. Each namespace needs its loopback up (bbw's DDS traffic stays on it).
#
# Like an ssh login, the command gets the user's SHELL (and a HOME) when the caller's environment
# lacks them: GNU parallel's remote wrapper runs the job with $SHELL, and with SHELL unset (as in
# a CI job's environment) it runs nothing and still exits 0.
set -euo pipefail
[ $# -ge 1 ] || { echo "netns-ssh: usage: netns-ssh.sh NAMESPACE -- COMMAND..." >&2; exit 255; }
ns="$1"; shift
[ "${1:-}" = "--" ] && shift
# (bash itself sets SHELL when it is missing, but does not export it: export it.)
export SHELL="${SHELL:-$(getent passwd "$(id -u)" | cut -d: -f7)}"
export SHELL="${SHELL:-/bin/sh}" HOME="${HOME:-/}"
exec ip netns exec "$ns" bash -c "$*"
