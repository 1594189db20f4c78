#!/usr/bin/env bash
# What the GPU machine runs (issue 3): the CUDA tests, the benchmark sweep,
# and the CPU rows with 2 threads. Executables are built on the dev machine
# with nvcc and carried in .devrun/ with their libraries in .devlibs/
# (docs/PERFORMANCE.md, "How to reproduce"). Logs and tables go to $OUT.
set -uo pipefail
out=${OUT:-out}
mkdir -p "$out"
export LD_LIBRARY_PATH=$PWD/.devlibs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
run=.devrun
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem,power.limit --format=csv | tee "$out/device.txt"
lscpu | grep -E "Model name|^CPU\(s\)" | tee -a "$out/device.txt"

echo "== CUDA tests"
timeout 300 $run/morph_cuda_test > "$out/cuda_test.log" 2>&1
grep -E "^\[  (PASSED|FAILED|SKIPPED) |Failure" "$out/cuda_test.log" | head -20
echo "== CPU tests (there too)"
timeout 120 $run/morph_test 2>&1 | tail -3 | tee "$out/cpu_test.log"

echo "== bench: full sweep"
timeout 330 $run/morph --sizes 256,1024,4096 --lines 40,84,100 --keys 2,7 --backends cuda,fast,thesis \
  --fast-cells 8,16 --fast-reach 4 --runs 50 --out "$out/bench_full.md" 2>"$out/bench_full.err"
tail -3 "$out/bench_full.err"
echo "== bench: CPU, 2 threads on this host"
EMOFACE_THREADS=2 timeout 120 $run/morph --sizes 256,512 --lines 84 --keys 2,7 --backends cpu \
  --fast-cells 8 --fast-reach 1,4 --runs 50 --cpu-budget 10 --out "$out/bench_cpu2.md" 2>/dev/null | grep "^|"
