#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Installs the Debian packages dissgen needs to build and run (the demo), and
# with --tests those the tests add, if any are missing. Uses sudo when not root.
set -euo pipefail
packages=(cmake g++ make pkg-config libwireshark-dev tshark libglib2.0-dev libxml2-dev
          libgtest-dev python3 util-linux libjs-dygraphs)
# The fuzz test's compiler and runtime, the browser that checks the report's page.
test_packages=(clang libclang-rt-14-dev chromium)
[ "${1:-}" = "--tests" ] && packages+=("${test_packages[@]}")
missing=()
for p in "${packages[@]}"; do
  # (No `| grep -q`: under pipefail its early exit could fail the query and
  # count an installed package as missing.)
  [[ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null)" == *"install ok installed"* ]] || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "installing: ${missing[*]}"
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
$sudo apt-get update -q
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q "${missing[@]}"
