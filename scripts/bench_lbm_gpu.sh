#!/usr/bin/env bash
# The LBM on a GPU beside the same binary on the CPU, in one run (docs/performance.md, "LBM on
# a GPU"). Usage: scripts/bench_lbm_gpu.sh [BINARY] [N...]
#
# BINARY: a granflow built with `cargo build --release --features gpu` (default
# target/release/granflow); N: lattice sides (default 2048 4096). Prints the adapter, then one
# JSON line per run: f32 and f64 (f64 only where the adapter has SHADER_F64), BGK and MRT,
# 100 steps per repeat, median of 5, with the device's own copy bandwidth and the roofline
# fraction; then the CPU at the first size for the ratio; then the seed's Table 5.3 coupled case
# (2400 × 3000 cells, 2500 grains, 100 coupled steps, f32) with the lattice on the GPU and on
# the CPU. Kept short so that a lent GPU's time goes to measuring: ≈ 2 minutes on a data-centre
# GPU with 16 cores beside it.
set -uo pipefail
bin="${1:-target/release/granflow}"
shift || true
sizes=("$@")
[ ${#sizes[@]} -eq 0 ] && sizes=(2048 4096)
command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader
command -v vulkaninfo >/dev/null && vulkaninfo --summary 2>/dev/null | grep -E "deviceName|driverInfo|apiVersion" | head -6
for n in "${sizes[@]}"; do
  for p in f32 f64; do
    for c in bgk mrt; do
      "$bin" bench lbm --backend gpu --nx "$n" --ny "$n" --steps 100 --repeats 5 \
        --precision "$p" --collision "$c" --json || echo "{\"n\": $n, \"precision\": \"$p\", \"collision\": \"$c\", \"error\": true}"
    done
  done
done
"$bin" bench lbm --backend cpu --nx "${sizes[0]}" --ny "${sizes[0]}" --steps 20 --repeats 3 --precision f32 --json
for b in gpu cpu; do
  "$bin" bench coupled --backend "$b" --nx 2400 --ny 3000 --grains 2500 --steps 100 --json \
    || echo "{\"coupled\": \"$b\", \"error\": true}"
done
