#!/usr/bin/env bash
# Benchmark `asperity bem` against tamaas and ContactMechanics (see bench/bem_peers.py).
# Creates bench/.venv (git-ignored) with both peers from PyPI, builds asperity in release
# mode, and runs the comparison; results go to bench/out/ (results.json, results.md and the
# Markdown tables on stdout). Extra arguments are passed to bem_peers.py, e.g.
#   bench/bem_peers.sh --sizes 256,512 --solvers bccg,pk --threads 2,1
# (--solvers: values of `asperity bem --solver`; a binary without that flag runs pk only).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x bench/.venv/bin/python ]; then
    python3 -m venv bench/.venv
    bench/.venv/bin/pip install --quiet --upgrade pip
fi
# Pinned: the versions the published tables (README, docs/bem.md) were measured with;
# CCG without restart lives in NuMPI. bem_peers.py records what is installed in results.json.
bench/.venv/bin/pip install --quiet tamaas==2.9.0 ContactMechanics==1.8.3 NuMPI==0.18.1 \
    SurfaceTopography==1.27.1 numpy
cargo build --release -p asperity-cli
# asperity runs on the thread counts of --threads (default 2 and 1); the peers run on one
# thread (tamaas' PyPI wheel is its serial "cpp" backend; numpy FFTs are serial).
exec bench/.venv/bin/python bench/bem_peers.py --asperity target/release/asperity --out bench/out "$@"
