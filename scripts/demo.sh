#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The main job, on a fresh Debian bookworm machine: install what is missing,
# build, generate the EtherCAT plugin from rules/ethercat.xml and decode the
# shipped sample capture with tshark.
#
# The plugin goes into a throw-away HOME so your own Wireshark set-up is left
# alone (for yourself, run: build/bin/dissgen install rules/ethercat.xml).
# Wireshark run as root ignores per-user plugins, so as root tshark runs as
# the unprivileged user "nobody".
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh

version=$(pkg-config --modversion wireshark | cut -d. -f1,2)
demo_home=$(mktemp -d /tmp/dissgen-demo-XXXXXX)
trap 'rm -rf "$demo_home"' EXIT
build/bin/dissgen install rules/ethercat.xml --dir "$demo_home/.local/lib/wireshark/plugins/$version/epan"
cp samples/ethercat-demo.pcap "$demo_home/"
chmod -R a+rX "$demo_home"

tshark_as_user() {
  if [ "$(id -u)" -eq 0 ]; then
    setpriv --reuid=65534 --regid=65534 --clear-groups env HOME="$demo_home" tshark "$@"
  else
    HOME="$demo_home" tshark "$@"
  fi
}
capture="$demo_home/ethercat-demo.pcap"
echo
echo "== tshark -r samples/ethercat-demo.pcap (summary lines)"
tshark_as_user -r "$capture"
echo
echo "== tshark -V, frame 8: the tree built from rules/ethercat.xml"
tshark_as_user -r "$capture" -V -O ecatr -Y "frame.number == 8"
echo
echo "== display filter on a rule field: ecatr.datagram.cmd == 0x0c (LRW)"
tshark_as_user -r "$capture" -Y "ecatr.datagram.cmd == 0x0c" -T fields -e frame.number \
  -e ecatr.datagram.lad -e ecatr.datagram.wkc -E occurrence=a -E aggregator=, | head -5
