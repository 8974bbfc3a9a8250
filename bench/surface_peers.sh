#!/usr/bin/env bash
# Surface-generation benchmark against the Python peers, measured side by side.
# Usage: bench/surface_peers.sh            (N=4096 REPEAT=5 by default)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p asperity-cli
if [ ! -x bench/.venv/bin/python ]; then
    python3 -m venv bench/.venv
fi
bench/.venv/bin/pip install -q numpy tamaas SurfaceTopography
bench/.venv/bin/python -c 'import importlib.metadata as m; print(" ".join(f"{p} {m.version(p)}" for p in ("numpy", "SurfaceTopography", "tamaas")))'
OMP_NUM_THREADS=2 RAYON_NUM_THREADS=2 bench/.venv/bin/python bench/surface_peers.py
