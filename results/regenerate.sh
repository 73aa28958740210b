#!/usr/bin/env bash
# Regenerates the committed evidence in results/: the convergence study of
# every scenario family (results/converge/<scenario>/) and the benchmark
# (results/bench.md). Run from the repository root:
#
#     bash results/regenerate.sh            # everything (about 10-20 minutes)
#     bash results/regenerate.sh converge   # the convergence studies only
#     bash results/regenerate.sh bench      # the benchmark only
#     bash results/regenerate.sh converge-direct  # the direct approach's studies only
#
# Every study uses the same settings so they can be compared: pitches 4, 2,
# 1 and 0.5 mm (0.25 mm too on the wave and the depression), angles -30, 0
# and 30 degrees, 60 seeded starts (seed 1), tolerance 1 mm, SPEC's default
# strike rule (deflection 0.5 degrees, e0 1e-6 mm) and tie band.
set -euo pipefail
cd "$(dirname "$0")/.."
what="${1:-all}"
cargo build --release --quiet
bin=target/release/kneeform

if [[ "$what" == all || "$what" == converge ]]; then
  for file in scenarios/*.toml; do
    name=$(basename "$file" .toml)
    pitches=4,2,1,0.5
    # The wave and the depression also at 0.25 mm (SPEC's smooth parts,
    # cheap enough); the console stops at 0.5 mm (12 million nodes).
    [[ "$name" == wave || "$name" == depression ]] && pitches=4,2,1,0.5,0.25
    echo "== $name"
    "$bin" converge "$file" --pitches "$pitches" --angles=-30,0,30 --starts 60 --seed 1 \
      --tolerance 1 --out "results/converge/$name"
  done
fi

if [[ "$what" == all || "$what" == converge || "$what" == converge-direct ]]; then
  # The direct approach (issue 12) against its exact oracle on the smooth
  # parts, turned by --frame -y,x,z so that their surface faces +x, towards
  # the knee-form coming from +x. Same pitches, angles, starts and seed.
  for name in tilted-wave wave ramp; do
    echo "== $name (direct)"
    "$bin" converge "scenarios/$name.toml" --frame=-y,x,z --approach direct \
      --pitches 4,2,1,0.5 --angles=-30,0,30 --starts 60 --seed 1 \
      --tolerance 1 --out "results/converge-direct/$name"
  done
fi

if [[ "$what" == all || "$what" == bench ]]; then
  "$bin" bench --runs 5 --markdown results/bench.md
fi
