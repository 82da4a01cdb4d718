#!/usr/bin/env bash
# The Python package in CI: install it (after `cargo test --release --workspace`, this compiles
# only pyo3 and the bindings) and run its tests against the merge_sim built by cargo test.
set -euo pipefail
cd "$(dirname "$0")"
pip=(python3 -m pip install --quiet --disable-pip-version-check --root-user-action=ignore)
# Pinned: the versions the suite was written and checked against (2026-12-02; pettingzoo 2026-12-03).
"${pip[@]}" "maturin==1.16.0" "numpy==2.4.6" "pandas==3.1.1" "gymnasium==1.4.0" "pytest==9.2.0" \
    "matplotlib==3.11.2" "scipy==1.17.1" "statsmodels==0.15.0" "pyarrow==26.0.1" \
    "commonroad-io==2026.1" "commonroad-vehicle-models==3.0.2" "pettingzoo==1.25.0"
# No build isolation: the maturin just installed builds it (no second download).
started=$SECONDS
"${pip[@]}" --no-build-isolation .
echo "pip install ./python: $((SECONDS - started)) s"
# From tests/, so that the installed package is imported, not the sources beside it.
cd tests
MERGESIM_BIN="${MERGESIM_BIN:-$PWD/../../target/release/merge_sim}" python3 -m pytest -q -p no:cacheprovider
