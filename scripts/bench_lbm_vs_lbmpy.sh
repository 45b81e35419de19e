#!/usr/bin/env bash
# Compare granflow's D2Q9 kernel with lbmpy on this machine, alternating the two so both see the
# same conditions. Usage: scripts/bench_lbm_vs_lbmpy.sh [N=2048] [rounds=3]
# Needs ../shared/peers (the project's peer scripts) beside the repository.
set -euo pipefail
cd "$(dirname "$0")/.."
N="${1:-2048}"; ROUNDS="${2:-3}"
PEERS="../shared/peers"
cargo build --release --quiet
for round in $(seq 1 "$ROUNDS"); do
  for prec in f32 f64; do
    lp=$([ "$prec" = f32 ] && echo fp32 || echo fp64)
    for t in 1 2; do
      echo "== round $round $prec threads=$t"
      ./target/release/granflow bench lbm --nx "$N" --ny "$N" --steps 100 --precision "$prec" --collision bgk --threads "$t" --repeats 3 --json
      [ "$t" = 2 ] && ./target/release/granflow bench lbm --nx "$N" --ny "$N" --steps 100 --precision "$prec" --collision mrt --threads "$t" --repeats 3 --json
      QUIET_MAX_WAIT=20 REPEATS=3 bash "$PEERS/lbmpy.sh" "$t" "$lp" "$N" 100 vec 2>&1 | grep -E "PEER|spread"
    done
  done
done
