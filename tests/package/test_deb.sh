#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The Debian package, for real: build it with CPack, install it, use it as a
# user would (outside the source tree), remove it and check nothing is left.
# It installs and removes system files, so it runs only in CI (CI set) as root
# on a disposable machine; otherwise it prints SKIPPED and exits 77.
#
#   test_deb.sh --build-dir BUILD --source-dir SRC [--deb FILE] [--keep]
#
# --deb FILE tests an existing package instead of running cpack in BUILD.
set -u

build_dir="" source_dir="" deb="" keep=0
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build_dir="$2"; shift 2 ;;
    --source-dir) source_dir="$2"; shift 2 ;;
    --deb) deb="$2"; shift 2 ;;
    --keep) keep=1; shift ;;
    *) echo "usage: $0 --build-dir BUILD --source-dir SRC [--deb FILE] [--keep]" >&2; exit 2 ;;
  esac
done
[ -n "$build_dir" ] && [ -n "$source_dir" ] ||
  { echo "usage: $0 --build-dir BUILD --source-dir SRC [--deb FILE] [--keep]" >&2; exit 2; }
build_dir=$(cd "$build_dir" && pwd) source_dir=$(cd "$source_dir" && pwd)

if [ -z "${CI:-}" ] || [ "$(id -u)" -ne 0 ]; then
  echo "SKIPPED: installs and removes the dissgen package system-wide: runs only as root with CI set"
  exit 77
fi
for tool in dpkg dpkg-deb apt-get cpack tshark setpriv readelf man; do
  command -v "$tool" >/dev/null || { echo "SKIPPED: $tool is not installed"; exit 77; }
done
if dpkg-query -W -f='${Status}' dissgen 2>/dev/null | grep -q "install ok installed"; then
  echo "FAILED: a dissgen package is already installed; this test needs a machine without it"
  exit 1
fi

passed=0 failed=0
ok() { echo "ok: $1"; passed=$((passed + 1)); }
not_ok() { echo "FAILED: $1"; failed=$((failed + 1)); }
check() {  # check DESCRIPTION COMMAND...: passes when the command succeeds
  local what="$1"; shift
  if "$@"; then ok "$what"; else not_ok "$what"; fi
}
step() { echo; echo "== $1 ($(( $(date +%s) - t0 ))s)"; }
t0=$(date +%s)

work=$(mktemp -d /tmp/dissgen-deb.XXXXXX)
chmod 755 "$work"
installed_by_us=0
cleanup() {
  rm -f "$plugin_dir/dissgen_ethercat-root.so"
  if dpkg-divert --list 2>/dev/null | grep -q "dissgen-packaged-ethercat.so"; then
    dpkg-divert --local --rename --remove "$plugin_dir/dissgen-packaged-ethercat.so" >/dev/null 2>&1
  fi
  if [ "$installed_by_us" = 1 ] && dpkg-query -W -f='${Status}' dissgen 2>/dev/null | grep -q installed; then
    echo "(cleanup: purging the dissgen package)"
    dpkg --purge dissgen >/dev/null 2>&1
  fi
  [ "$keep" = 1 ] && echo "(kept $work)" || rm -rf "$work"
}
trap cleanup EXIT

plugin_dir="$(pkg-config --variable=plugindir wireshark)/epan"
abi=$(pkg-config --modversion wireshark | grep -oE '^[0-9]+\.[0-9]+')
next_abi="${abi%.*}.$(( ${abi#*.} + 1 ))"
libws=$(readlink -f "$(pkg-config --variable=libdir wireshark)/libwireshark.so")
libws_package=$(dpkg -S "$libws" | head -1 | cut -d: -f1)
packaged_plugin="$plugin_dir/dissgen-packaged-ethercat.so"

# as_user HOME CMD...: run as the unprivileged user 65534 with that HOME (Wireshark
# run as root ignores per-user plugins; a user installs into their own HOME).
as_user() {
  local home="$1"; shift
  setpriv --reuid=65534 --regid=65534 --clear-groups \
    env -i HOME="$home" PATH=/usr/bin:/bin LANG=C.UTF-8 TMPDIR=/tmp "$@"
}

# --- 1. build the package ---------------------------------------------------
step "build the package"
if [ -z "$deb" ]; then
  mkdir -p "$work/pkg"
  if (cd "$build_dir" && cpack -G DEB -B "$work/pkg") >"$work/cpack.log" 2>&1; then
    deb=$(ls "$work"/pkg/dissgen_*.deb 2>/dev/null | head -1)
  fi
  [ -n "$deb" ] && ok "cpack -G DEB built $(basename "$deb") ($(( $(date +%s) - t0 ))s)" ||
    { not_ok "cpack -G DEB: $(tail -20 "$work/cpack.log")"; echo "$passed passed, $failed failed"; exit 1; }
fi
deb=$(readlink -f "$deb")

# --- 2. what the package holds ----------------------------------------------
step "package contents and metadata"
dpkg-deb -I "$deb" control >"$work/control"
dpkg-deb -c "$deb" | awk '{print $NF}' | sed 's|^\./|/|' >"$work/contents"
sed 's/^/  /' "$work/control"
depends=$(grep '^Depends:' "$work/control")
check "Package: dissgen" grep -qx "Package: dissgen" "$work/control"
check "Depends bounds $libws_package (the owner of $libws) to $abi" \
  grep -qF "$libws_package (>= $abi), $libws_package (<< $next_abi)" <<<"$depends"
for dep in "libwireshark-dev (>= $abi)" "libwireshark-dev (<< $next_abi)" libxml2 libglib2.0-0 \
           libglib2.0-dev "g++ | c++-compiler" pkg-config; do
  check "Depends on $dep" grep -qF "$dep" <<<"$depends"
done
mkdir "$work/x"
dpkg-deb -x "$deb" "$work/x"
# The runtime files: every one the packaged dissgen compiles plugins from
# (`dissgen sources`, which reads plugin_runtime/runtime.list).
runtime_files=()
if listing=$("$work/x/usr/bin/dissgen" sources) && grep -q "^source " <<<"$listing"; then
  while read -r kind path; do
    [ "$kind" = source ] || [ "$kind" = header ] && runtime_files+=("/usr/share/dissgen/runtime/$path")
  done <<<"$listing"
else
  not_ok "the packaged dissgen lists the runtime it compiles plugins from (dissgen sources)"
fi
for f in /usr/bin/dissgen "${runtime_files[@]}" \
         /usr/share/dissgen/rules/ethercat.xml "$packaged_plugin" /usr/share/man/man1/dissgen.1.gz \
         /usr/share/doc/dissgen/copyright; do
  check "contains $f" grep -qx "$f" "$work/contents"
done
check "everything is under /usr, nothing in /usr/local" \
  bash -c '! grep -v "^/usr/" "$1" | grep -q . && ! grep -q "^/usr/local" "$1"' _ "$work/contents"
leaks=$(grep -rlF -e "$source_dir" -e "$build_dir" -e /usr/local "$work/x" 2>/dev/null)
check "no build or /usr/local path inside any file${leaks:+ (found in: $leaks)}" test -z "$leaks"
copyright="$work/x/usr/share/doc/dissgen/copyright"
check "the copyright file is machine-readable (DEP-5), GPL-2+ for all files" \
  bash -c 'head -1 "$1" | grep -q "^Format: https://www.debian.org/doc/packaging-manuals/copyright-format/1.0/" &&
           grep -q "^Files: \*$" "$1" && grep -q "^License: GPL-2+$" "$1" &&
           grep -q "/usr/share/common-licenses/GPL-2" "$1"' _ "$copyright"
# lintian, when it is there or can be installed (CI): no error, no copyright complaint.
command -v lintian >/dev/null ||
  DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends lintian >"$work/lintian-apt.log" 2>&1
if command -v lintian >/dev/null; then
  lintian "$deb" >"$work/lintian" 2>&1
  sed 's/^/  lintian: /' "$work/lintian"
  check "lintian reports no error and nothing about the copyright file" \
    bash -c '! grep -q "^E: " "$1" && ! grep -qi "copyright" "$1"' _ "$work/lintian"
else
  echo "  (lintian not available: not run)"
fi
unstripped=$(find "$work/x" -type f \( -name '*.so' -o -path '*/bin/*' \) -exec sh -c \
  'readelf -S "$1" | grep -q "\.debug_info" && echo "$1"' _ {} \;)
check "binaries are stripped${unstripped:+ (not: $unstripped)}" test -z "$unstripped"

# --- 3. install -------------------------------------------------------------
step "install"
find "$plugin_dir" -maxdepth 1 | sort >"$work/plugins-before"
if DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "$deb" >"$work/apt.log" 2>&1; then
  installed_by_us=1
  ok "apt-get install $(basename "$deb")"
else
  installed_by_us=1
  not_ok "apt-get install: $(tail -20 "$work/apt.log")"
  echo "$passed passed, $failed failed"; exit 1
fi
dpkg -L dissgen | sort >"$work/dpkg-L"
check "dissgen is /usr/bin/dissgen" test "$(command -v dissgen)" = /usr/bin/dissgen
check "dissgen --version" bash -c 'dissgen --version | grep -q "^dissgen [0-9]"'

# --- 4. a user's own protocol, from a folder outside the source tree ---------
step "a user's protocol on ethertype 0x88b5"
user_home="$work/home"
mkdir -p "$user_home/project"
cat >"$user_home/project/sensor.xml" <<'EOF'
<root name="Made-up Sensor Protocol" abbreviation="MSP" ethertype="0x88b5">
  <node name="Version" length="1byte" displaytype="numberdec"/>
  <node name="Kind" length="1byte" displaytype="enum">
    <enum value="1" name="Temperature"/>
    <enum value="2" name="Pressure"/>
  </node>
  <node name="Value" length="2byte" displaytype="numberhex"/>
</root>
EOF
# One Ethernet frame 02:..:02 -> ff:..:ff, ethertype 0x88b5, payload 01 02 be ef 12 34 + padding.
python3 - "$user_home/project/sensor.pcap" <<'EOF'
import struct, sys
frame = b"\xff" * 6 + b"\x02" * 6 + b"\x88\xb5" + bytes([1, 2, 0xbe, 0xef, 0x12, 0x34]) + bytes(40)
with open(sys.argv[1], "wb") as fh:
    fh.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1))
    fh.write(struct.pack("<IIII", 1, 0, len(frame), len(frame)) + frame)
EOF
chown -R 65534:65534 "$user_home"
cd "$user_home/project"
user_plugin="$user_home/.local/lib/wireshark/plugins/$abi/epan/dissgen_sensor.so"
# decode FIELDS...: tshark as the user on sensor.pcap; stdout in $work/out, stderr in $work/err.
decode() {
  local args=(-r "$user_home/project/sensor.pcap" -T fields -E separator=,)
  for f in "$@"; do args+=(-e "$f"); done
  as_user "$user_home" tshark "${args[@]}" >"$work/out" 2>"$work/err"
}
if as_user "$user_home" dissgen install sensor.xml >"$work/out" 2>"$work/err"; then
  ok "dissgen install sensor.xml (as the user): $(cat "$work/out")"
else
  not_ok "dissgen install sensor.xml: $(cat "$work/out" "$work/err")"
fi
check "the plugin is in the user's plugin folder" test -s "$user_plugin"
as_user "$user_home" tshark -G plugins >"$work/plugins" 2>"$work/plugins.err"
check "tshark -G plugins lists it, with no loader warning" \
  bash -c 'grep -q "dissgen_sensor.so" "$1" && ! grep -q . "$2"' _ "$work/plugins" "$work/plugins.err"
decode msp.version msp.kind msp.value _ws.col.Protocol
check "tshark decodes it: $(cat "$work/out")" grep -qx "1,0x02,0xbeef,MSP" "$work/out"
check "tshark wrote nothing on stderr" test ! -s "$work/err"
as_user "$user_home" tshark -r "$user_home/project/sensor.pcap" -V >"$work/out" 2>&1
check "the tree shows the protocol and the enum's name" \
  bash -c 'grep -q "^Made-up Sensor Protocol" "$1" && grep -q "Kind: Pressure (0x02)" "$1"' _ "$work/out"

step "edit the rules and install again"
sed -i 's|<node name="Value" length="2byte" displaytype="numberhex"/>|<node name="Reading" length="4byte" displaytype="numberhex"/>|' sensor.xml
if as_user "$user_home" dissgen install sensor.xml >"$work/out" 2>"$work/err"; then
  ok "dissgen install of the edited sensor.xml"
else
  not_ok "dissgen install of the edited sensor.xml: $(cat "$work/out" "$work/err")"
fi
decode msp.version msp.reading
check "the decode follows the edit: $(cat "$work/out")" grep -qx "1,0xbeef1234" "$work/out"
decode msp.value
check "the old field is gone" grep -q "msp.value" "$work/err"
cd "$work"

# --- 5. the packaged EtherCAT plugin, for root -------------------------------
step "the packaged EtherCAT plugin serves root's tshark"
cp "$source_dir/samples/ethercat-demo.pcap" "$work/ecat.pcap"
chmod 644 "$work/ecat.pcap"
mkdir -p "$work/roothome"
HOME="$work/roothome" tshark -G plugins >"$work/plugins" 2>"$work/plugins.err"
check "root's tshark lists dissgen-packaged-ethercat.so" grep -q "dissgen-packaged-ethercat.so" "$work/plugins"
HOME="$work/roothome" tshark -r "$work/ecat.pcap" -c 3 -T fields -e _ws.col.Protocol -e ecatr.datagram.cmd \
  -e ecatr.datagram.wkc >"$work/out" 2>"$work/err"
check "0x88a4 decodes with the rules (ECATR, commands): $(tr '\n' ' ' <"$work/out")" \
  bash -c 'test "$(wc -l <"$1")" = 3 && ! grep -qv "^ECATR	0x[0-9a-f]" "$1"' _ "$work/out"
check "no plugin warning for root" bash -c '! grep -v "Running as user" "$1" | grep -q .' _ "$work/err"

# --- 6. a user's edited copy of the packaged rules replaces them for the user --
step "a user's copy of the EtherCAT rules overrides the packaged plugin"
# Renames the node and every reference to it (a peek looks ahead at the working counter).
sed -e 's/name="Working counter"/name="Edited working counter"/' \
    -e "s/@name='Working counter'/@name='Edited working counter'/g" /usr/share/dissgen/rules/ethercat.xml \
  >"$user_home/project/ethercat.xml"
chown 65534:65534 "$user_home/project/ethercat.xml"
(cd "$user_home/project" && as_user "$user_home" dissgen install ethercat.xml) >"$work/out" 2>"$work/err"
check "dissgen install ethercat.xml (the user's copy) succeeds" test $? -eq 0
check "... and notes that it replaces $packaged_plugin for the user" \
  grep -qF "note: the dissgen package's $packaged_plugin provides protocol 'ecatr' too" "$work/err"
as_user "$user_home" tshark -r "$work/ecat.pcap" -c 1 -V >"$work/out" 2>"$work/err"
check "the user's tshark decodes with the edited rules" grep -q "Edited working counter:" "$work/out"
check "the packaged plugin stepped aside quietly (same protocol: no clash report)" \
  bash -c '! grep -q "not loaded" "$1"' _ "$work/err"
HOME="$work/roothome" tshark -r "$work/ecat.pcap" -c 1 -V >"$work/out" 2>/dev/null
check "root's tshark keeps the packaged rules" \
  bash -c 'grep -q "Working counter:" "$1" && ! grep -q "Edited" "$1"' _ "$work/out"
cp "$user_home/project/ethercat.xml" "$work/ethercat-root.xml"
dissgen install --system "$work/ethercat-root.xml" >"$work/out" 2>"$work/err"
rc=$?
check "dissgen install --system of the same protocol is refused, pointing to dpkg-divert" \
  bash -c 'test "$1" = 1 && grep -q "dpkg-divert --local --rename" "$2"' _ "$rc" "$work/err"
check "... and installs nothing" test ! -e "$plugin_dir/dissgen_ethercat-root.so"

step "replacing the packaged plugin for everyone, as dissgen.1 says (dpkg-divert)"
diverted="$packaged_plugin.disabled"
dpkg-divert --local --rename --divert "$diverted" --add "$packaged_plugin" >/dev/null 2>&1
check "dpkg-divert set the packaged plugin aside" bash -c 'test -e "$1" && test ! -e "$2"' _ "$diverted" "$packaged_plugin"
dissgen install --system "$work/ethercat-root.xml" >"$work/out" 2>"$work/err"
check "dissgen install --system now installs $plugin_dir/dissgen_ethercat-root.so" \
  test -e "$plugin_dir/dissgen_ethercat-root.so"
HOME="$work/roothome" tshark -G plugins >"$work/plugins" 2>&1
check "Wireshark ignores the diverted file" bash -c '! grep -q "dissgen-packaged-ethercat" "$1"' _ "$work/plugins"
HOME="$work/roothome" tshark -r "$work/ecat.pcap" -c 1 -V >"$work/out" 2>"$work/err"
check "root's tshark decodes with the edited rules, no message" \
  bash -c 'grep -q "Edited working counter:" "$1" && ! grep -v "Running as user" "$2" | grep -q .' _ "$work/out" "$work/err"
rm -f "$plugin_dir/dissgen_ethercat-root.so"
dpkg-divert --local --rename --remove "$packaged_plugin" >/dev/null 2>&1
check "dpkg-divert --rename --remove puts the packaged plugin back" \
  bash -c 'test -e "$1" && test ! -e "$2" && ! dpkg-divert --list | grep -q dissgen' _ "$packaged_plugin" "$diverted"

# --- 7. man page, version check of the installed dissgen ----------------------
step "man page"
check "man -w dissgen finds /usr/share/man/man1/dissgen.1.gz" \
  test "$(man -w dissgen 2>/dev/null)" = /usr/share/man/man1/dissgen.1.gz
MANPAGER=cat MANWIDTH=80 man dissgen >"$work/man.txt" 2>"$work/man.err"
check "man dissgen renders (NAME, SYNOPSIS, PACKAGED PLUGINS)" \
  bash -c 'grep -q "^NAME" "$1" && grep -q "dissgen install" "$1" && grep -q "^PACKAGED PLUGINS" "$1"' _ "$work/man.txt"
check "man page renders without warnings" \
  bash -c '! LC_ALL=C.UTF-8 man --warnings -l /usr/share/man/man1/dissgen.1.gz 2>&1 >/dev/null | grep -q .'

step "the installed dissgen refuses a Wireshark of another minor release"
if bash "$source_dir/tests/package/test_version_mismatch.sh" --dissgen /usr/bin/dissgen >"$work/out" 2>&1; then
  ok "test_version_mismatch.sh with /usr/bin/dissgen: $(tail -1 "$work/out")"
else
  not_ok "test_version_mismatch.sh with /usr/bin/dissgen:"; sed 's/^/    /' "$work/out"
fi

# --- 8. remove --------------------------------------------------------------
step "remove"
if dpkg --purge dissgen >"$work/purge.log" 2>&1; then
  installed_by_us=0
  ok "dpkg --purge dissgen"
else
  not_ok "dpkg --purge dissgen: $(cat "$work/purge.log")"
fi
check "dpkg no longer knows dissgen" bash -c '! dpkg-query -W -f="\${Status}" dissgen 2>/dev/null | grep -q installed'
left=""
while read -r f; do
  [ -z "$f" ] && continue
  if [ -e "$f" ] && [ ! -d "$f" ]; then left="$left $f"; fi
done <"$work/dpkg-L"
check "every file dpkg -L listed is gone${left:+ (left:$left)}" test -z "$left"
check "/usr/share/dissgen is gone" test ! -e /usr/share/dissgen
check "/usr/share/doc/dissgen is gone" test ! -e /usr/share/doc/dissgen
check "/usr/bin/dissgen is gone" test ! -e /usr/bin/dissgen
find "$plugin_dir" -maxdepth 1 | sort >"$work/plugins-after"
plugins_changed=$(diff "$work/plugins-before" "$work/plugins-after" | grep '^[<>]' | tr '\n' ' ' || true)
check "the plugin folder is as before the install${plugins_changed:+ (changed: $plugins_changed)}" \
  test -z "$plugins_changed"
HOME="$work/roothome" tshark -r "$work/ecat.pcap" -c 1 -T fields -e _ws.col.Protocol >"$work/out" 2>"$work/err"
check "root's tshark is back to Wireshark's own EtherCAT dissector ($(cat "$work/out"))" \
  grep -qx "ECAT" "$work/out"

echo
echo "$passed passed, $failed failed ($(( $(date +%s) - t0 ))s)"
[ "$failed" -eq 0 ]
