#!/usr/bin/env bash
# Write the seed checkpoints of cairn_fuzz_checkpoint (tests/robustness/fuzz_checkpoint.cpp) from
# the inputs in inputs/: each run stops after 3 steps and leaves its checkpoint (MPM 1D; 2D with
# contact, a wall and state variables; 3D APIC with temperatures; WLS; WLS bodies in contact; FEM;
# and the 2D contact case on 2 MPI ranks, whose particles are stored rank after rank).
# Usage, from the repository root: tests/robustness/corpus/checkpoint/make_seeds.sh [build/release/cairn]
set -euo pipefail
cairn="$(realpath "${1:-build/release/cairn}")"
here="$(cd "$(dirname "$0")" && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"
for input in mpm_1d mpm_2d_contact mpm_3d_apic_thermal wls_2d wls_2d_contact fem_2d; do
  "$cairn" run -q -t 1 "$here/inputs/$input.toml" --set simulation.max_steps=3 --set output.directory="\"$work/$input\""
  cp "$work/$input"/checkpoint-0000.h5 "$here/seeds/$input.h5"
done
mpirun --allow-run-as-root --oversubscribe -np 2 "$cairn" run -q -t 1 "$here/inputs/mpm_2d_contact.toml" \
  --set simulation.max_steps=3 --set output.directory="\"$work/ranks\""
cp "$work/ranks/checkpoint-0000.h5" "$here/seeds/mpm_2d_contact_2ranks.h5"
ls -l "$here/seeds"
