#!/usr/bin/env bash
# Stall reasons of the exact kernel (4096², N = 100, K = 2) and the fast
# apply pass (4096², N = 100, K = 7) on the GPU machine; logs to $OUT.
set -uo pipefail
out=${OUT:-out}
export LD_LIBRARY_PATH=$PWD/.devlibs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
m=".devrun/morph --runs 3 --warmup 2 --error-max-size 0"
for spec in "exact warp_kernel --sizes 4096 --lines 100 --keys 2 --backends cuda" \
            "apply apply_kernel --sizes 4096 --lines 100 --keys 7 --backends fast" \
            "grid warp_kernel --sizes 4096 --lines 100 --keys 7 --backends fast"; do
  set -- $spec; name=$1; k=$2; shift 2
  timeout 90 ncu --clock-control none -k "regex:$k" --launch-skip 12 --launch-count 1 \
    --metrics "regex:smsp__warp_issue_stalled_.*_per_warp_active.pct,sm__throughput.avg.pct_of_peak_sustained_elapsed,gpu__time_duration.sum,sm__warps_active.avg.pct_of_peak_sustained_active" \
    $m "$@" > "$out/stall_$name.txt" 2>&1
  echo "== $name"; grep -E "stalled|duration|throughput|warps_active" "$out/stall_$name.txt" | awk '$NF+0 > 1.0 || /duration|throughput|warps_active/' | sed 's/smsp__warp_issue_stalled_//'
done
