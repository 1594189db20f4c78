#!/usr/bin/env bash
# What the GPU machine runs (issue 3): the CUDA tests, then the benchmark
# sweep. Executables are built here with nvcc and carried in .devrun/ with
# their libraries in .devlibs/ (see docs/PERFORMANCE.md, "How to reproduce").
# Usage on the device: bench/gpu_run.sh [quick]; logs go to $OUT (or ./out).
set -uo pipefail
out=${OUT:-out}
mkdir -p "$out"
export LD_LIBRARY_PATH=$PWD/.devlibs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
run=.devrun
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem,power.limit --format=csv | tee "$out/device.txt"
nproc | sed 's/^/host cores: /' | tee -a "$out/device.txt"

echo "== CUDA tests"
timeout 300 $run/morph_cuda_test 2>&1 | tee "$out/cuda_test.log" | grep -E "^\[  (PASSED|FAILED|SKIPPED) |OK \]|FAILED|Failure|error" | tail -40
echo "== CPU tests (there too)"
timeout 120 $run/morph_test 2>&1 | tail -3 | tee "$out/cpu_test.log"

if [ "${1:-}" = quick ]; then
  timeout 200 $run/morph --sizes 256,4096 --lines 84,100 --keys 2,7 --backends cuda,fast,thesis --runs 50 \
    --out "$out/bench_quick.md" 2>&1 | tail -30
  exit 0
fi
echo "== bench: full sweep"
timeout 330 $run/morph --sizes 256,1024,4096 --lines 40,84,100 --keys 2,7 --backends cuda,fast,thesis \
  --fast-cells 8,16 --fast-reach 4 --runs 50 --out "$out/bench_full.md" 2>"$out/bench_full.err"
tail -5 "$out/bench_full.err"
cat "$out/bench_full.md"
echo "== bench: points a thread (4096², N = 100, K = 2)"
timeout 60 $run/morph --sizes 4096 --lines 100 --keys 2 --backends cuda --px 1,4,8 --runs 50 \
  --out "$out/bench_px.md" 2>/dev/null | grep "cuda"
echo "== bench: line split off (256², N = 84)"
EMOFACE_MORPH_SPLIT=0 timeout 60 $run/morph --sizes 256 --lines 84 --keys 2,7 --backends cuda --runs 50 \
  --out "$out/bench_nosplit.md" 2>/dev/null | grep "cuda"
echo "== bench: fast cell and reach (4096², N = 100, K = 7)"
timeout 120 $run/morph --sizes 4096 --lines 100 --keys 7 --backends fast --fast-cells 8,16,32 --fast-reach 1,2,4 \
  --runs 50 --out "$out/bench_fast.md" 2>/dev/null | grep "fast"
