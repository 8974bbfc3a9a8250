#!/usr/bin/env bash
# Builds the Python package and runs its test suite, on a machine with only a Rust
# toolchain, Python >= 3.9 and pip (network to PyPI and crates.io).
#
#   python/ci.sh            # from anywhere; PYTHON=python3.12 python/ci.sh to pick one
#   python/ci.sh --deps-only   # steps 1-2 only (.ci/run downloads them while Rust compiles)
#
# 1. a virtual environment python/.venv (git-ignored; reused when present);
# 2. the build and test dependencies from PyPI: maturin, numpy, pytest, matplotlib, scipy
#    and xarray (scipy's netcdf_file and xarray read the NetCDF files test_netcdf.py
#    writes; xarray with pandas installs in about 8 s here) and the peers
#    ContactMechanics + SurfaceTopography (the cross-check tests need them);
# 3. the `asperity` binary the tests compare against (ASPERITY_BIN, else cargo build
#    --release), then `pip install ./python` (maturin builds the abi3 extension in the
#    root's target/);
# 4. pytest on python/tests. Exit status: pytest's, except that "no tests collected"
#    (pytest's 5) is a failure too.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
python="${PYTHON:-python3}"
venv="$here/.venv"
start=$(date +%s)
deps_only=0
for arg in "$@"; do
    case "$arg" in
    --deps-only) deps_only=1 ;;
    *) echo "usage: python/ci.sh [--deps-only]" >&2 && exit 2 ;;
    esac
done

if [ ! -x "$venv/bin/python" ]; then
    "$python" -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --upgrade pip
"$venv/bin/python" -m pip install --quiet "maturin>=1.16,<2" numpy pytest matplotlib \
    scipy xarray ContactMechanics SurfaceTopography
if [ "$deps_only" = 1 ]; then
    echo "python/ci.sh: test dependencies in $venv after $(( $(date +%s) - start )) s" >&2
    exit 0
fi

# The CLI the tests compare with: ASPERITY_BIN where given (.ci/run passes the binary its
# Rust tests built), else a release build here.
if [ -z "${ASPERITY_BIN:-}" ] || [ ! -x "$ASPERITY_BIN" ]; then
    (cd "$repo" && cargo build --release --quiet -p asperity-cli)
    export ASPERITY_BIN="$repo/target/release/asperity"
fi

# The README's install command (from the repository root). The extension builds in the
# root's target/ (CARGO_TARGET_DIR): the dependencies it shares with the CLI's build are not
# compiled twice (measured on a clean clone: 148 s instead of 204 s on 2 cores).
(cd "$repo" && CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$repo/target}" \
    "$venv/bin/python" -m pip install --quiet ./python)

# From the repository root, not python/: there the source folder python/asperity (without
# the compiled module) would shadow the installed package.
cd "$repo"
status=0
MPLBACKEND=Agg "$venv/bin/python" -m pytest -q -p no:cacheprovider "$here/tests" || status=$?
if [ "$status" -eq 5 ]; then
    echo "python/ci.sh: pytest collected no tests" >&2
    status=1
fi
echo "python/ci.sh: exit $status after $(( $(date +%s) - start )) s" >&2
exit "$status"
