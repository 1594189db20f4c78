#!/usr/bin/env bash
# Profiling pass on the GPU machine (issue 3 tuning): SASS of the morph
# kernels and Nsight Compute sections for the exact kernel (4096², N = 100,
# K = 2), the small-image kernel (256², N = 84, K = 2) and the fast mode's
# passes (4096², N = 100, K = 7). Logs go to $OUT.
set -uo pipefail
out=${OUT:-out}
mkdir -p "$out"
export LD_LIBRARY_PATH=$PWD/.devlibs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
run=.devrun
cuobjdump -sass $run/morph | gzip > "$out/sass.txt.gz"
sections="--section SpeedOfLight --section ComputeWorkloadAnalysis --section WarpStateStats --section InstructionStats --section Occupancy --section MemoryWorkloadAnalysis --section LaunchStats"
prof() {  # name, kernel regex, bench args...
  local name=$1 regex=$2; shift 2
  timeout 120 ncu --clock-control none -k "regex:$regex" --launch-skip 12 --launch-count 1 $sections \
    $run/morph --runs 3 --warmup 2 --error-max-size 0 "$@" > "$out/ncu_$name.txt" 2>&1
  grep -E "Duration|Compute \(SM\) Throughput|Memory Throughput|Issue Slots Busy|Executed Ipc A|Achieved Occupancy|Registers Per|L1/TEX Hit|L2 Hit|Stall|Warp Cycles Per Issued" "$out/ncu_$name.txt" | head -20
}
echo "== exact 4096 K2"; prof exact4096 "warp_kernel" --sizes 4096 --lines 100 --keys 2 --backends cuda
echo "== exact 256 K2"; prof exact256 "warp_kernel" --sizes 256 --lines 84 --keys 2 --backends cuda
echo "== fast apply 4096 K7"; prof apply4096 "apply_kernel" --sizes 4096 --lines 100 --keys 7 --backends fast --fast-cells 8
echo "== fast grid 4096 K7"; prof grid4096 "warp_kernel" --sizes 4096 --lines 100 --keys 7 --backends fast --fast-cells 8
