#!/usr/bin/env bash
# Benchmark `asperity bem` against tamaas and ContactMechanics (see bench/bem_peers.py).
# Creates bench/.venv (git-ignored) with both peers from PyPI, builds asperity in release
# mode, and runs the comparison; results go to bench/out/ (results.json and a Markdown
# table on stdout). Extra arguments are passed to bem_peers.py, e.g. --sizes 256,512.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x bench/.venv/bin/python ]; then
    python3 -m venv bench/.venv
    bench/.venv/bin/pip install --quiet --upgrade pip
fi
# Pinned: the versions the published table (README, docs/bem.md) was measured with;
# bem_peers.py records what is installed in its results.json.
bench/.venv/bin/pip install --quiet tamaas==2.9.0 ContactMechanics==1.8.3 numpy
cargo build --release -p asperity-cli
# Both peers and asperity get the machine's cores (tamaas' PyPI wheel is serial, its
# "cpp" backend; numpy FFTs in ContactMechanics are serial too).
exec bench/.venv/bin/python bench/bem_peers.py --asperity target/release/asperity --out bench/out "$@"
