#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# `dissgen install` builds only when the Wireshark headers (pkg-config
# --modversion wireshark) and the installed Wireshark (tshark --version) are the
# same major.minor release: Wireshark's loader rejects any other plugin with
# just a warning. A fake tshark (or pkg-config) early on PATH fakes a mismatch.
#
#   test_version_mismatch.sh --dissgen PATH      (e.g. build/bin/dissgen or /usr/bin/dissgen)
set -u

dissgen=""
while [ $# -gt 0 ]; do
  case "$1" in
    --dissgen) dissgen="$2"; shift 2 ;;
    *) echo "usage: $0 --dissgen PATH" >&2; exit 2 ;;
  esac
done
[ -x "$dissgen" ] || { echo "usage: $0 --dissgen PATH (no executable '$dissgen')" >&2; exit 2; }
if ! headers=$(pkg-config --modversion wireshark 2>/dev/null); then
  echo "SKIPPED: no Wireshark development files (pkg-config wireshark)"
  exit 77
fi
major_minor=$(echo "$headers" | grep -oE '^[0-9]+\.[0-9]+')
other_minor="${major_minor%.*}.$(( ${major_minor#*.} + 2 ))"      # 4.0 -> 4.2

work=$(mktemp -d "${TMPDIR:-/tmp}/dissgen-version.XXXXXX")
trap 'rm -rf "$work"' EXIT
passed=0
failed=0
ok() { echo "ok: $1"; passed=$((passed + 1)); }
not_ok() { echo "FAILED: $1"; failed=$((failed + 1)); }

cat > "$work/sensor.xml" <<'EOF'
<root name="Version Test Protocol" abbreviation="VTP" ethertype="0x88b5">
  <node name="Value" length="2byte" displaytype="numberhex"/>
</root>
EOF

# fake_tshark DIR VERSION: a tshark that only answers --version.
fake_tshark() {
  mkdir -p "$1"
  cat > "$1/tshark" <<EOF
#!/bin/sh
if [ "\$1" = "--version" ]; then
  echo "TShark (Wireshark) $2 (Git v$2 packaged as $2-1)"
  echo
  echo "Copyright 1998-2024 Gerald Combs <gerald@wireshark.org> and contributors."
  exit 0
fi
exit 1
EOF
  chmod +x "$1/tshark"
}

# install_with PATH_PREFIX: run dissgen install with PATH_PREFIX before PATH.
install_with() {
  rm -rf "$work/plugins"
  PATH="$1:$PATH" "$dissgen" install "$work/sensor.xml" --dir "$work/plugins" >"$work/out" 2>"$work/err"
}

# 1. tshark is another minor release than the headers: refused, clearly, nothing installed.
fake_tshark "$work/newer" "$other_minor.3"
if install_with "$work/newer"; then
  not_ok "tshark $other_minor.3 with $headers headers: dissgen install succeeded"
elif grep -q "headers are version $major_minor but tshark is $other_minor" "$work/err" &&
     grep -q "libwireshark-dev" "$work/err"; then
  ok "tshark $other_minor.3 with $headers headers: refused ($(head -c 150 "$work/err")...)"
else
  not_ok "tshark $other_minor.3: refused without the expected message: $(cat "$work/err")"
fi
[ -e "$work/plugins/dissgen_sensor.so" ] && not_ok "a plugin was installed despite the mismatch" \
  || ok "no plugin installed on a mismatch"

# 2. The headers are another release than tshark (a fake pkg-config --modversion).
mkdir -p "$work/oldheaders"
real_pkg_config=$(command -v pkg-config)
cat > "$work/oldheaders/pkg-config" <<EOF
#!/bin/sh
if [ "\$1" = "--modversion" ] && [ "\$2" = "wireshark" ]; then echo "3.6.2"; exit 0; fi
exec "$real_pkg_config" "\$@"
EOF
chmod +x "$work/oldheaders/pkg-config"
fake_tshark "$work/oldheaders" "$headers"
if install_with "$work/oldheaders"; then
  not_ok "3.6 headers with tshark $headers: dissgen install succeeded"
elif grep -q "headers are version 3.6 but tshark is $major_minor" "$work/err"; then
  ok "3.6 headers with tshark $headers: refused"
else
  not_ok "3.6 headers: refused without the expected message: $(cat "$work/err")"
fi

# 3. Only major.minor matters: another patch release of the same minor builds.
fake_tshark "$work/patch" "$major_minor.99"
if install_with "$work/patch" && [ -s "$work/plugins/dissgen_sensor.so" ]; then
  ok "tshark $major_minor.99 with $headers headers: built and installed"
else
  not_ok "tshark $major_minor.99 with $headers headers: not installed: $(cat "$work/err")"
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
