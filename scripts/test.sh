#!/usr/bin/env bash
# Installs the test dependencies and runs every test (cargo and pytest).
# This is the README's test command; .ci/run runs it verbatim.
set -euo pipefail
cd "$(dirname "$0")/.."
python3 -m pip install --disable-pip-version-check -q -e '.[test]'
# Headless Chromium renders the HTML report in its test (Debian's package).
if ! command -v chromium >/dev/null 2>&1; then
  if command -v apt-get >/dev/null 2>&1; then
    apt-get update -qq && apt-get install -y -qq chromium >/dev/null
  else
    echo "chromium is missing and apt-get is not available: the report browser test will skip" >&2
  fi
fi
cargo test --workspace --release
python3 -m ruff check python tests benchmarks examples
set +e
python3 -m pytest -q
status=$?
set -e
# pytest exit 5 means "no tests collected": that is a failure of the suite, not a pass.
exit $status
