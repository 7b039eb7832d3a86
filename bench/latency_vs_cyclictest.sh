#!/usr/bin/env bash
# Servo wake-up latency: rp-latency against cyclictest (Debian's rt-tests), one after the other,
# with the same rate, count, priority and CPU, on whatever load the machine has. Prints each
# one's p50 and p99 (both from 1 us histogram bins, the bin middle, as rp-latency computes them)
# and rp-latency's p99 over cyclictest's. Repeat with --runs N (alternating which goes first).
#   bench/latency_vs_cyclictest.sh [--rate HZ] [--duration S] [--priority P] [--affinity CPU]
#                                  [--runs N] [--bin DIR]
# Exit status 0; the figures are for reading (docs/realtime.md), never a pass/fail threshold.
set -euo pipefail
rate=1000 duration=10 priority=27 affinity="" runs=1
bin=$(cd "$(dirname "$0")/.." && pwd)/build/bin
while [ $# -gt 0 ]; do
  case "$1" in
    --rate) rate=$2; shift 2 ;;
    --duration) duration=$2; shift 2 ;;
    --priority) priority=$2; shift 2 ;;
    --affinity) affinity=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --bin) bin=$2; shift 2 ;;
    *) echo "latency_vs_cyclictest.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
command -v cyclictest >/dev/null || { echo "latency_vs_cyclictest.sh: cyclictest not found (Debian: rt-tests; scripts/install-deps)" >&2; exit 2; }
[ -x "$bin/rp-latency" ] || { echo "latency_vs_cyclictest.sh: $bin/rp-latency not built" >&2; exit 2; }
interval=$(awk -v r="$rate" 'BEGIN { printf "%d", 1e6 / r + 0.5 }')
loops=$(awk -v r="$rate" -v d="$duration" 'BEGIN { printf "%d", r * d + 0.5 }')
ct=(cyclictest -m -p "$priority" -i "$interval" -l "$loops" -q -h 10000)
rl=("$bin/rp-latency" --rate "$rate" --duration "$duration" --priority "$priority")
if [ -n "$affinity" ]; then ct+=(-a "$affinity"); rl+=(--affinity "$affinity"); fi
echo "cyclictest: ${ct[*]}"
echo "rp-latency: ${rl[*]}"

# p50 and p99 of a cyclictest histogram (lines "bin count" in us, "# Min Latencies: ..."), as
# rp-latency computes them: the middle of the first bin where the count reaches ceil(p * total),
# within [min, max].
cyclictest_percentiles() {
  awk '/^[0-9]+[ \t]+[0-9]+/ { n[$1 + 0] = $2; total += $2 }
       /^# Min Latencies/ { min = $4 + 0 } /^# Max Latencies/ { max = $4 + 0 }
       END {
         split("0.50 0.99", ps, " ");
         for (k = 1; k <= 2; ++k) {
           target = total * ps[k]; if (target > int(target)) target = int(target) + 1;
           seen = 0; v = max;
           for (b = 0; b < 10000; ++b) { seen += n[b]; if (seen >= target) { v = b + 0.5; break } }
           if (v < min) v = min; if (v > max) v = max;
           printf "%s%.1f", (k > 1 ? " " : ""), v
         }
         printf " %d %d\n", min, max
       }'
}

for ((r = 1; r <= runs; ++r)); do
  run_ct() { read -r c50 c99 cmin cmax < <("${ct[@]}" 2>/dev/null | cyclictest_percentiles); }
  run_rl() {
    out=$("${rl[@]}" 2>&1)
    read -r r50 r99 rmax < <(echo "$out" | awk '/^wake-up latency/ { print $7, $9, $11 }')
    sched=$(echo "$out" | awk -F': ' '/^scheduling:/ { print $2 }')
  }
  if (( r % 2 == 1 )); then run_ct; run_rl; else run_rl; run_ct; fi
  ratio=$(awk -v a="$r99" -v b="$c99" 'BEGIN { printf "%.2f", a / b }')
  printf 'run %d: cyclictest p50 %s p99 %s max %s us | rp-latency p50 %s p99 %s max %s us (%s) | p99 ratio %s\n' \
    "$r" "$c50" "$c99" "$cmax" "$r50" "$r99" "$rmax" "$sched" "$ratio"
done
