#!/usr/bin/env bash
# rp-latency (issue 17): it runs its cycles and prints its figures in cyclictest's form and as
# percentiles, uses SCHED_FIFO where the process may, and where it may not (capabilities
# CAP_SYS_NICE and CAP_IPC_LOCK dropped with capsh) says so once on stderr, runs with normal
# scheduling and still ends with status 0. No timing is asserted (docs/realtime.md has figures).
#   rp_latency.sh RP_LATENCY
set -euo pipefail
program=$1
scratch=$(mktemp -d "${TMPDIR:-/tmp}/rp-latency.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
fail() { echo "rp_latency: $*" >&2; exit 1; }

# run OUT ERR COMMAND...: the command's exit status must be 0 and its figures all there.
run() {
  local out=$1 err=$2
  shift 2
  local rc=0
  "$@" >"$out" 2>"$err" || rc=$?
  [[ $rc -eq 0 ]] || { cat "$out" "$err" >&2; fail "exit status $rc from: $*"; }
  grep -q '^rp-latency: 1000 Hz (interval 1000 us) for 0.5 s, 500 cycles$' "$out" || fail "no header line: $(cat "$out")"
  grep -Eq '^T: 0 \( *[0-9]+\) P: *[0-9]+ I:1000 C: +500 Min: +[0-9]+ Avg: +[0-9]+ Max: +[0-9]+$' "$out" ||
    fail "no cyclictest-style line with 500 cycles: $(cat "$out")"
  grep -Eq '^wake-up latency \[us\]: min [0-9.]+  p50 [0-9.]+  p99 [0-9.]+  max [0-9.]+  mean [0-9.]+$' "$out" ||
    fail "no percentile line: $(cat "$out")"
  grep -Eq '^overruns: [0-9]+$' "$out" || fail "no overrun count: $(cat "$out")"
}

# Unprivileged: the refusal is said once, the run goes on with normal scheduling.
if capsh --drop=cap_sys_nice,cap_ipc_lock -- -c true 2>/dev/null; then
  run "$scratch/out1" "$scratch/err1" capsh --drop=cap_sys_nice,cap_ipc_lock -- -c "exec $(printf '%q' "$program") --duration 0.5 -nogui"
  grep -q '^scheduling: normal (no permission for SCHED_FIFO)$' "$scratch/out1" || fail "not reported as normal scheduling: $(cat "$scratch/out1")"
  grep -q ' P: 0 ' "$scratch/out1" || fail "the cyclictest line does not show priority 0: $(cat "$scratch/out1")"
  n=$(grep -c 'cannot use SCHED_FIFO priority 27 (Operation not permitted)' "$scratch/err1" || true)
  [[ $n -eq 1 ]] || fail "the SCHED_FIFO refusal was said $n times, not once: $(cat "$scratch/err1")"
  m=$(grep -c 'mlockall failed' "$scratch/err1" || true)
  [[ $m -le 1 ]] || fail "the mlockall refusal was said $m times: $(cat "$scratch/err1")"
  echo "rp_latency: without CAP_SYS_NICE: normal scheduling, the refusal said once"
else
  echo "rp_latency: SKIPPED the unprivileged run: capsh cannot drop capabilities here"
fi

# Privileged (where the test may): SCHED_FIFO at the paper's priority 27, nothing refused.
if [[ $(id -u) -eq 0 ]]; then
  run "$scratch/out2" "$scratch/err2" "$program" --duration 0.5 -nogui
  grep -q '^scheduling: SCHED_FIFO$' "$scratch/out2" || fail "not SCHED_FIFO as root: $(cat "$scratch/out2")"
  grep -q ' P:27 ' "$scratch/out2" || fail "the cyclictest line does not show priority 27: $(cat "$scratch/out2")"
  ! grep -q 'cannot use SCHED_FIFO' "$scratch/err2" || fail "SCHED_FIFO refused as root: $(cat "$scratch/err2")"
  echo "rp_latency: as root: SCHED_FIFO priority 27"
else
  echo "rp_latency: SKIPPED the privileged run: not root"
fi
