#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Installs what is missing, builds, and runs every test (unit and integration) with ctest,
# then lists the tests that were skipped, each with its reason (tests/ctest_summary.py).
# Extra arguments go to ctest (e.g. -R test_enip).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh --tests
bash scripts/build.sh
cd build
rm -f ctest-junit.xml
status=0
# (Passed tests' output is kept, ends included, so that skip reasons reach the JUnit file.)
ctest --output-on-failure -j"$(nproc)" --output-junit ctest-junit.xml \
  --test-output-size-passed 65536 --test-output-truncation middle "$@" || status=$?
python3 ../tests/ctest_summary.py --junit ctest-junit.xml --build-dir . || status=1
exit "$status"
