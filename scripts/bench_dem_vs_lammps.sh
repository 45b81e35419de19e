#!/usr/bin/env bash
# Compare granflow's DEM step with LAMMPS (gran/hooke/history) on the in.gran2d.lmp case,
# alternating the two so both see the same conditions.
# Usage: scripts/bench_dem_vs_lammps.sh [rounds=3] [steps=5000]
# Needs ../shared/peers (the project's peer scripts) beside the repository; installs LAMMPS
# (Debian package) through the peer script on first use.
set -euo pipefail
cd "$(dirname "$0")/.."
ROUNDS="${1:-3}"; STEPS="${2:-5000}"
PEERS=../shared/peers
cargo build --release --quiet
BIN=target/release/granflow
lscpu | grep -m1 'Model name'
for r in $(seq 1 "$ROUNDS"); do
  for cfg in "10k 10000 1" "10k 10000 2" "40k 40000 2"; do
    read -r size n t <<<"$cfg"
    g="$("$BIN" bench dem --grains "$n" --steps "$STEPS" --repeats 3 --threads "$t" --json |
      python3 -c 'import json,sys; print("%.3g" % json.load(sys.stdin)["particle_steps_per_s"])')"
    l="$("$PEERS/lammps.sh" "$size" "$t" 3 "$STEPS" | sed -n 's/.*atom_steps_per_s=\([^ ]*\).*/\1/p')"
    echo "round $r N=$n threads=$t granflow=$g lammps=$l ratio=$(python3 -c "print('%.2f' % ($g/$l))")"
  done
done
