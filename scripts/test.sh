#!/usr/bin/env bash
# Every check of the project, in a fresh virtual environment: formatting and lints (cargo fmt,
# clippy, ruff), the Rust tests and the Python tests. This is the README's test command;
# .ci/run runs it verbatim.
#
# The environment `.venv-test` (git-ignored) is removed and created anew on every run and gets
# `.[test]` only, so a dependency that is not declared in pyproject.toml fails here instead of
# passing by accident. Cargo and maturin share one target folder (CARGO_TARGET_DIR), so the
# release build of the extension and `cargo test --release` share the compiled crates (rod,
# fatigue, volume, nalgebra, rayon, ...); only pyo3 and the binding crate differ between the two
# (the extension module does not link libpython, the test binaries do).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
start=$(date +%s)
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target}"

step() { printf '\n== %s (%ss)\n' "$1" "$(($(date +%s) - start))" >&2; }

step "cargo fmt --all --check"
cargo fmt --all --check

step "cargo clippy --workspace --all-targets -- -D warnings"
cargo clippy --workspace --all-targets --quiet -- -D warnings

step "fresh virtual environment .venv-test with .[test]"
venv=$root/.venv-test
rm -rf "$venv"
python3 -m venv "$venv"
py=$venv/bin/python
"$py" -m pip install --disable-pip-version-check -q -e '.[test]'

# Headless Chromium renders the HTML report in its test (Debian's package). It is installed
# only when this runs as root; a failing apt-get does not end the run (the test then skips
# and says what is missing).
if ! command -v chromium >/dev/null 2>&1 && ! command -v chromium-browser >/dev/null 2>&1; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    step "apt-get install chromium"
    { apt-get update -qq && apt-get install -y -qq chromium >/dev/null; } ||
      echo "apt-get could not install chromium: the report's browser test will skip" >&2
  else
    echo "chromium is not installed (and this is not root with apt-get): the report's browser" \
      "test will skip; install Debian's 'chromium' package to run it" >&2
  fi
fi

step "cargo test --workspace --release"
cargo test --workspace --release --quiet

step "ruff"
"$py" -m ruff check python tests benchmarks examples

step "pytest"
set +e
"$py" -m pytest -q
status=$?
set -e
# pytest exit 5 means "no tests collected": that is a failure of the suite, not a pass.
if [ "$status" = 5 ]; then
  echo "pytest collected no tests: failing" >&2
  status=1
fi
step "done, exit $status"
exit "$status"
