#!/usr/bin/env bash
# Figure 23 with one Puma behind a hardware server (rp-hwserver -board puma560: a Puma 560 wired to
# an I/O board) and the other simulated: the program completes and prints the largest difference.
set -euo pipefail
hwserver=$1 program=$2 work=$3
name="svr-$$"
mkdir -p "$work"
printf '[puma]\nclass Puma560\nsimulationMode off\nhwserver %s\n' "$name" > "$work/rp.cfg"
# Emptied here, not by the server's redirection below: that happens in the child, and the wait
# loop could read the previous run's "serving" line first.
: > "$work/hwserver.log"
# -watchdog 5000: a servo loop stalled by a loaded test machine is not cut off by the server.
"$hwserver" -name "$name" -rate 1000 -board puma560 -watchdog 5000 -duration 120 > "$work/hwserver.log" 2>&1 &
server=$!
trap 'kill $server 2>/dev/null || true; wait $server 2>/dev/null || true' EXIT
for _ in $(seq 1 100); do grep -q "serving" "$work/hwserver.log" && break; sleep 0.1; done
# -nosim: the second arm, declared without hardware, is switched to simulation by the program.
timeout 100 "$program" -nogui -nosim -config "$work/rp.cfg"
