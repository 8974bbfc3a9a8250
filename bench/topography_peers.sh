#!/usr/bin/env bash
# Measured-topography benchmark (issue 11): read a 4096² X3P (stored and deflated) and SUR
# file and compute their statistics, asperity against SurfaceTopography, side by side.
# Uses bench/.venv (made by bench/bem_peers.sh, or here); files and results in bench/out/.
#   bench/topography_peers.sh [--n 4096] [--repeat 3]
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x bench/.venv/bin/python ]; then
    python3 -m venv bench/.venv
    bench/.venv/bin/pip install --quiet --upgrade pip
fi
bench/.venv/bin/pip install --quiet SurfaceTopography==1.27.1 numpy
cargo build --release -p asperity-cli
exec bench/.venv/bin/python bench/topography_peers.py --asperity target/release/asperity "$@"
