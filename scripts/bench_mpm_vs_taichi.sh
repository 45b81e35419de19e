#!/usr/bin/env bash
# Compare granflow's MPM step (uGIMP, MUSL, Mohr–Coulomb collapse) with Taichi's MLS-MPM on this
# machine, alternating the two (and optionally an older granflow binary) so all see the same
# conditions. Usage: scripts/bench_mpm_vs_taichi.sh [rounds=3] [other granflow binary]
# Needs ../shared/peers (the project's peer scripts) beside the repository.
set -euo pipefail
cd "$(dirname "$0")/.."
ROUNDS="${1:-3}"; OTHER="${2:-}"
PEERS="../shared/peers"
cargo build --release --quiet
rate() { "$1" bench mpm --points "$2" --steps 200 --repeats 5 --threads 2 --json |
  python3 -c "import json,sys; print('%.3e' % json.load(sys.stdin)['point_steps_per_s'])"; }
for round in $(seq 1 "$ROUNDS"); do
  for n in 8192 32768; do
    [ -n "$OTHER" ] && echo "round $round n $n other    $(rate "$OTHER" "$n")"
    echo "round $round n $n granflow $(rate ./target/release/granflow "$n")"
    echo "round $round n $n taichi   $(bash "$PEERS/taichi.sh" "$n" 2 2>&1 | grep PEER | sed 's/.*particle_steps_per_s=//')"
  done
done
