#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The main job, on a fresh Debian bookworm machine: install what is missing,
# build, generate the EtherCAT plugin from rules/ethercat.xml and decode the
# shipped captures with tshark:
#   samples/replay-sdo-error.pcapng  real traffic (ethercrab master, one EK1914):
#                                    the bus scan, CoE mailbox exchanges (SDO
#                                    uploads, one aborted), repeated DC frames
#   samples/ethercat-demo.pcap       generated frames with cyclic process data (LRW)
# (samples/README says where they come from.) Then it writes the timing
# report of the real capture (dissgen report) into the build folder and says
# where it is: it opens offline in any browser (none is installed).
#
# The plugin goes into a throw-away HOME so your own Wireshark set-up is left
# alone (for yourself, run: build/bin/dissgen install rules/ethercat.xml).
# Wireshark run as root ignores per-user plugins, so as root tshark runs as
# the unprivileged user "nobody".
# Under `set -o pipefail` a reader that stops early (head, grep -q) kills the
# writer with SIGPIPE and fails the script, depending on timing: every reader
# here reads its input to the end (awk 'NR <= N' instead of head).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh --target dissgen # (the demo needs dissgen alone: a third of the whole build)

version=$(pkg-config --modversion wireshark | cut -d. -f1,2)
demo_home=$(mktemp -d /tmp/dissgen-demo-XXXXXX)
trap 'rm -rf "$demo_home"' EXIT
build/bin/dissgen install rules/ethercat.xml --dir "$demo_home/.local/lib/wireshark/plugins/$version/epan"
cp samples/replay-sdo-error.pcapng samples/ethercat-demo.pcap "$demo_home/"
chmod -R a+rX "$demo_home"

as_user() {
  if [ "$(id -u)" -eq 0 ]; then
    setpriv --reuid=65534 --regid=65534 --clear-groups env HOME="$demo_home" "$@"
  else
    HOME="$demo_home" "$@"
  fi
}
tshark_as_user() { as_user tshark "$@"; }
section() { echo; echo "== $1"; }
real="$demo_home/replay-sdo-error.pcapng"
generated="$demo_home/ethercat-demo.pcap"
# Frames as the slaves returned them: the first slave sets the locally
# administered bit of the master's source address (10:10:... -> 12:10:...).
returned="eth.src == 12:10:10:10:10:10"

# (Counts are taken in assignments, so that a failing tshark stops the script.)
frames=$(tshark_as_user -r "$real" | wc -l)
section "samples/replay-sdo-error.pcapng, a real capture: $frames frames, ECATR in the Protocol column"
tshark_as_user -r "$real" -c 6

section "the bus scan: what came back (BRD counts the slaves in the working counter, APWR gives the one slave station address 0x1000)"
echo "frame  ADP     ADO     WKC  Info"
tshark_as_user -r "$real" -Y "frame.number <= 24 && $returned" -T fields \
  -e frame.number -e _ws.col.Info -e ecatr.datagram.adp -e ecatr.datagram.ado -e ecatr.datagram.wkc |
  awk -F'\t' '{printf "%5s  %-7s %-7s %-4s %s\n", $1, $3, $4, $5, $2}'

section "a mailbox exchange: CoE SDO uploads written to the slave's mailbox (ADO 0x1000), answers read back (0x1100)"
echo "(the rules decode the mailbox: mailbox header, CoE header, SDO command, index and subindex, in the Info column)"
echo "frame  ADO     abort code  Info"
tshark_as_user -r "$real" \
  -Y "$returned && ecatr.datagram.wkc == 1 && (ecatr.datagram.ado == 0x1000 || ecatr.datagram.ado == 0x1100)" \
  -T fields -e frame.number -e _ws.col.Info -e ecatr.datagram.ado -e ecatr.datagram.mbx.coe.sdoreq.abortcode |
  awk -F'\t' '{printf "%5s  %-7s %-11s %s\n", $1, $3, $4, $2}' | tail -6
echo "(frame 544: the slave aborts the upload, object 0x1001 does not exist, abort code 0x06020000)"

section "frame 544 as Wireshark's tree shows it, from rules/ethercat.xml"
tshark_as_user -r "$real" -V -O ecatr -Y "frame.number == 544" | sed -n '/^EtherCAT/,$p' | cut -c1-100

dc_returned=$(tshark_as_user -r "$real" -Y "ecatr.datagram.cmd == 0x0e && $returned" | wc -l)
section "repeated frames: distributed-clock drift compensation, FRMW of the system time (ADO 0x0910), $dc_returned returned"
echo "(working counter 0: no slave processed them, as with the BWR to 0x0910 in the scan)"
echo "frame  time        ADO     WKC  Info"
tshark_as_user -r "$real" -Y "ecatr.datagram.cmd == 0x0e && $returned" -T fields \
  -e frame.number -e frame.time_relative -e _ws.col.Info -e ecatr.datagram.ado -e ecatr.datagram.wkc |
  awk -F'\t' 'NR <= 4 {printf "%5s  %.6f s  %-7s %-4s %s\n", $1, $2, $4, $5, $3}'

section "cyclic process data (LRW, logical addressing), from the generated samples/ethercat-demo.pcap"
echo "(lengths and working counters: one per datagram of the frame; data: the LRW's)"
echo "frame  logical address  lengths  WKC    data"
tshark_as_user -r "$generated" -Y "ecatr.datagram.cmd == 0x0c" -T fields -e frame.number \
  -e ecatr.datagram.lad -e ecatr.datagram.len -e ecatr.datagram.data -e ecatr.datagram.wkc \
  -E occurrence=a -E aggregator=, |
  awk -F'\t' 'NR <= 5 {printf "%5s  %-16s %-8s %-6s %s\n", $1, $2, $3, $5, $4}'

# dissgen report runs tshark itself, so it runs as that user too, from a copy
# that user can read, writing where that user may.
report="build/demo-report.html"
cp build/bin/dissgen "$demo_home/dissgen"
mkdir "$demo_home/report"
[ "$(id -u)" -ne 0 ] || chown 65534:65534 "$demo_home/report"
section "the timing report of samples/replay-sdo-error.pcapng (dissgen report: round trips, the slave's AL states)"
as_user "$demo_home/dissgen" report "$real" -o "$demo_home/report/demo-report.html"
cp "$demo_home/report/demo-report.html" "$report"
echo "report: $(pwd)/$report (one page, opens offline in any browser)"
