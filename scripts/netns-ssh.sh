#!/usr/bin/env bash
# An `ssh` for GNU parallel whose hosts are Linux network namespaces on this machine (root):
#   ./bbw campaign SPEC --out DIR --ssh scripts/netns-ssh.sh --sshlogin 1/NS_A --sshlogin 1/NS_B
# parallel calls it as `netns-ssh.sh NS -- COMMAND...` (what it would give ssh); the command runs
# in namespace NS through `ip netns exec`, sharing this machine's file system as a shared-file-
# system cluster does. Each namespace needs its loopback up (bbw's DDS traffic stays on it).
set -euo pipefail
[ $# -ge 1 ] || { echo "netns-ssh: usage: netns-ssh.sh NAMESPACE -- COMMAND..." >&2; exit 255; }
ns="$1"; shift
[ "${1:-}" = "--" ] && shift
exec ip netns exec "$ns" bash -c "$*"
