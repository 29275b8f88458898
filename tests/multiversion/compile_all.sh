#!/usr/bin/env bash
# Compiles the plugin runtime and the generated C++ of every rule file
# (rules/*.xml, tests/rules/*.xml, tests/rules_ok/*.xml) against the Wireshark
# headers of every Wireshark a user may have:
#   - the system's (pkg-config wireshark; 4.0 on Debian bookworm),
#   - Debian trixie's and sid's libwireshark-dev, libwsutil-dev and
#     libwiretap-dev (4.4 and 4.6 when this was written), fetched with
#     apt-get download into a private apt state (the machine's apt state and
#     sources are only read, never changed) and unpacked with dpkg-deb -x.
# Compile only (-c at -Og, with the project's warning flags and -Werror), plus a look
# at each generated object: the plugin entry points are exported and
# plugin_want_major/minor equal the version of the headers compiled against.
#
# Prints one line per (Wireshark version, file) and "N passed, N failed".
# Exit status: 0 all passed; 1 a failure; 2 bad usage or missing dissgen;
# 77 (after compiling against the system's headers) when the Debian archive
# cannot be reached: "SKIPPED: <reason>".
#
# Usage: tests/multiversion/compile_all.sh [--dissgen PATH] [--keep]
# Environment: CXX (default c++); DISSGEN_DEBIAN_MIRROR overrides the mirror
# taken from the machine's apt sources; DISSGEN_MULTIVERSION_SUITES (default
# "trixie sid").
# SPDX-License-Identifier: GPL-2.0-or-later
set -uo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
dissgen="$root/build/bin/dissgen"
keep=0
while [ $# -gt 0 ]; do
  case "$1" in
    --dissgen) dissgen="$2"; shift 2 ;;
    --dissgen=*) dissgen="${1#*=}"; shift ;;
    --keep) keep=1; shift ;;
    -h|--help) sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "compile_all.sh: unknown argument $1 (try --help)" >&2; exit 2 ;;
  esac
done
if [ ! -x "$dissgen" ]; then
  echo "compile_all.sh: no dissgen at $dissgen: build first (bash scripts/build.sh) or pass --dissgen PATH" >&2
  exit 2
fi
cxx="${CXX:-c++}"
suites="${DISSGEN_MULTIVERSION_SUITES:-trixie sid}"
packages=(libwireshark-dev libwsutil-dev libwiretap-dev)
# The runtime's sources (the generic ones and every analysis's: each is
# compiled here) and the options of plugin code, from the one list
# (plugin_runtime/runtime.list) as dissgen reads it, plus -Wall -Wextra -Werror:
# a deprecation is an error here.
if ! listing=$("$dissgen" sources); then
  echo "compile_all.sh: $dissgen sources failed" >&2
  exit 2
fi
runtime_sources=()
while read -r kind path; do
  [ "$kind" = source ] && runtime_sources+=("plugin_runtime/$path")
done <<<"$listing"
read -ra plugin_flags <<<"$(sed -n 's/^flags//p' <<<"$listing")"
# -Og, not the build's -O2: what this checks is the API of each Wireshark (errors,
# deprecations, the flow warnings -Og still runs), and generated code compiles a third
# faster (the build itself compiles it at -O2 against the system's headers).
flags=(-std=c++17 -Og -fPIC "${plugin_flags[@]}" -Wall -Wextra -Werror -I"$root/plugin_runtime")

work=$(mktemp -d "${TMPDIR:-/tmp}/dissgen-multiversion-XXXXXX")
cleanup() { if [ "$keep" = 1 ]; then echo "kept $work"; else rm -rf "$work"; fi; }
trap cleanup EXIT
started=$(date +%s)

# --- the mirror: the host the machine's own apt sources use for Debian -----

# Prints the URI of the first enabled "deb" source that serves this machine's
# release codename (not -security/-updates), from sources.list, *.list and
# deb822 *.sources alike.
machine_mirror() {
  local codename
  codename=$(. /etc/os-release 2>/dev/null && echo "${VERSION_CODENAME:-}")
  [ -n "$codename" ] || return 1
  local files=()
  [ -f /etc/apt/sources.list ] && files+=(/etc/apt/sources.list)
  local f
  for f in /etc/apt/sources.list.d/*.list /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] && files+=("$f")
  done
  [ ${#files[@]} -gt 0 ] || return 1
  awk -v want="$codename" '
    function flush() {
      if (types ~ /(^| )deb( |$)/ && enabled !~ /^(no|false)$/ && (" " suites " ") ~ (" " want " ")) {
        n = split(uris, u, " ")
        for (i = 1; i <= n; i++) if (u[i] ~ /^https?:\/\//) { print u[i]; found = 1; exit }
      }
      types = ""; uris = ""; suites = ""; enabled = ""
    }
    FNR == 1 { flush(); deb822 = (FILENAME ~ /\.sources$/) }
    /^[ \t]*#/ { next }
    deb822 && /^[ \t]*$/ { flush(); next }
    deb822 {
      key = tolower($1); sub(/:$/, "", key); $1 = ""; sub(/^ +/, "")
      if (key == "types") types = $0
      else if (key == "uris") uris = $0
      else if (key == "suites") suites = $0
      else if (key == "enabled") enabled = tolower($0)
      next
    }
    $1 == "deb" {
      line = $0; gsub(/\[[^]]*\]/, "", line); split(line, w, /[ \t]+/)
      types = "deb"; uris = w[2]; suites = w[3]; flush()
    }
    END { if (!found) flush() }
  ' "${files[@]}"
}

# --- fetching a suite's headers ------------------------------------------

skip_reason=""
apt_dir="$work/apt"
apt_opts=()
setup_apt() {
  local mirror="$1"
  mkdir -p "$apt_dir/state/lists/partial" "$apt_dir/cache/archives/partial" "$apt_dir/etc"
  local keyring=/usr/share/keyrings/debian-archive-keyring.gpg signed=""
  [ -f "$keyring" ] && signed=" [signed-by=$keyring]"
  local s
  for s in $suites; do echo "deb$signed $mirror $s main"; done > "$apt_dir/etc/sources.list"
  local arch
  arch=$(dpkg --print-architecture)
  apt_opts=(
    -o "Dir::State=$apt_dir/state" -o "Dir::State::status=/dev/null"
    -o "Dir::Cache=$apt_dir/cache"
    -o "Dir::Etc::SourceList=$apt_dir/etc/sources.list" -o "Dir::Etc::SourceParts=/dev/null"
    -o "Dir::Etc::Preferences=/dev/null" -o "Dir::Etc::PreferencesParts=/dev/null"
    -o "APT::Architecture=$arch" -o "APT::Architectures=$arch" -o "Acquire::Languages=none"
    -o "Acquire::Retries=1" -o "Acquire::http::Timeout=30" -o "Acquire::https::Timeout=30"
    -o "APT::Sandbox::User=root")
  [ "$(id -u)" -eq 0 ] || apt_opts=("${apt_opts[@]:0:${#apt_opts[@]}-2}")
}

network_trouble='Could not resolve|Temporary failure resolving|Could not connect|Unable to connect|Connection failed|Connection timed out|timed out|Network is unreachable|No route to host|Failed to fetch|Unable to fetch'

fetch_indexes() {
  local log="$apt_dir/update.log"
  if ! apt-get "${apt_opts[@]}" update >"$log" 2>&1 || grep -Eq "$network_trouble" "$log"; then
    if grep -Eq "$network_trouble" "$log"; then
      skip_reason="the Debian archive at $1 cannot be reached: $(grep -Em1 "$network_trouble" "$log" | sed "s/^[[:space:]]*//" | cut -c1-160)"
      return 1
    fi
    echo "compile_all.sh: apt-get update with the private apt state failed:" >&2
    sed 's/^/  /' "$log" >&2
    return 2
  fi
}

# Downloads and unpacks one suite's packages into $work/ws-SUITE; prints
# nothing, returns non-zero with the reason in fetch_error.
fetch_error=""
fetch_suite() {
  local suite="$1" dest="$work/ws-$1" debs="$work/debs-$1"
  mkdir -p "$dest" "$debs"
  local specs=() p
  for p in "${packages[@]}"; do specs+=("$p/$suite"); done
  if ! (cd "$debs" && apt-get "${apt_opts[@]}" download "${specs[@]}") >"$debs/download.log" 2>&1; then
    fetch_error="apt-get download ${specs[*]} failed: $(grep -E '^(E|W):' "$debs/download.log" | head -3 | tr '\n' ' ')"
    return 1
  fi
  local deb
  for deb in "$debs"/*.deb; do
    dpkg-deb -x "$deb" "$dest" || { fetch_error="dpkg-deb -x $(basename "$deb") failed"; return 1; }
  done
}

# --- compile flags per Wireshark -----------------------------------------

# Fills ws_cflags for the headers under $1 (empty: the system's): what
# pkg-config --cflags wireshark gives with the package's wireshark.pc, its
# paths moved under $1, plus glib's (from its Requires).
ws_cflags=""
ws_version=""
cflags_for() {
  local dest="$1"
  if [ -z "$dest" ]; then
    if ! ws_cflags=$(pkg-config --cflags wireshark 2>/dev/null); then
      fetch_error="pkg-config finds no wireshark (install libwireshark-dev)"
      return 1
    fi
    ws_version=$(pkg-config --modversion wireshark)
    return 0
  fi
  local pc
  pc=$(find "$dest" -name wireshark.pc -path '*pkgconfig*' | head -1)
  [ -n "$pc" ] || { fetch_error="the packages hold no wireshark.pc"; return 1; }
  mkdir -p "$dest/.pc"
  # prefix=/usr, libdir=/usr/lib/..., includedir=/usr/include: absolute values move under $dest.
  sed -E "s#^([A-Za-z_]+)=/#\\1=$dest/#" "$pc" > "$dest/.pc/wireshark.pc"
  ws_version=$(PKG_CONFIG_PATH="$dest/.pc" pkg-config --modversion wireshark 2>/dev/null)
  if ! ws_cflags=$(PKG_CONFIG_PATH="$dest/.pc" pkg-config --cflags wireshark 2>/dev/null); then
    # Its Requires (glib) may ask for more than this machine has: the same by hand.
    ws_cflags="-I$(find "$dest" -type d -path '*/include/wireshark' | head -1) $(pkg-config --cflags glib-2.0 gmodule-2.0)"
    ws_version=$(sed -n 's/^Version: *//p' "$pc")
  fi
  case " $ws_cflags " in *" -I$dest/"*) ;; *) fetch_error="wireshark.pc of $dest gives no include path inside it: $ws_cflags"; return 1 ;; esac
}

# --- the files -----------------------------------------------------------

rule_files=()
for pattern in rules/*.xml tests/rules/*.xml tests/rules_ok/*.xml; do
  for f in "$root"/$pattern; do [ -f "$f" ] && rule_files+=("${f#"$root"/}"); done
done

# Generates each rule file once (the output does not depend on the headers).
declare -A generated gen_error
i=0
for rel in "${rule_files[@]}"; do
  i=$((i + 1))
  out="$work/gen/$i"
  mkdir -p "$out"
  if "$dissgen" generate "$root/$rel" -o "$out" >"$out.log" 2>&1; then
    generated[$rel]=$(ls "$out"/*.cpp 2>/dev/null | head -1)
    [ -n "${generated[$rel]}" ] || gen_error[$rel]="dissgen generate wrote no .cpp"
  else
    gen_error[$rel]="dissgen generate failed: $(grep -m3 'error' "$out.log" | tr '\n' ' ')"
  fi
done

# --- checks ----------------------------------------------------------------

passed=0
failed=0
report() { # STATUS LABEL FILE [DETAIL...]
  local status="$1" label="$2" file="$3"
  shift 3
  printf '%-4s  %-18s %s\n' "$status" "$label" "$file"
  if [ "$status" = PASS ]; then passed=$((passed + 1)); else failed=$((failed + 1)); fi
  [ $# -gt 0 ] && printf '%s\n' "$@" | head -40 | sed 's/^/      /'
  return 0
}

# The 4-byte int value of a defined symbol in an object file.
symbol_int() {
  local obj="$1" sym="$2" line section offset
  line=$(objdump -t "$obj" | awk -v s="$sym" '$NF == s { print; exit }')
  [ -n "$line" ] || return 1
  section=$(awk '{ for (i = 1; i <= NF; i++) if ($i ~ /^\./) { print $i; exit } }' <<<"$line")
  offset=$((16#$(awk '{ print $1 }' <<<"$line")))
  objcopy -O binary --only-section="$section" "$obj" "$obj.$section" 2>/dev/null || return 1
  od -An -t d4 -j "$offset" -N 4 "$obj.$section" | tr -d ' '
}

# What a generated plugin object must export for the loader of version $2.
check_plugin_object() {
  local obj="$1" version="$2" major minor sym problems=()
  major=${version%%.*}
  minor=${version#*.}; minor=${minor%%.*}
  local exports
  exports=$(nm -g --defined-only "$obj" | awk '{ print $NF }')
  local wanted=(plugin_version plugin_want_major plugin_want_minor plugin_register)
  if [ "$major" -gt 4 ] || { [ "$major" -eq 4 ] && [ "$minor" -ge 4 ]; }; then wanted+=(plugin_describe); fi
  for sym in "${wanted[@]}"; do
    grep -qx "$sym" <<<"$exports" || problems+=("does not export $sym")
  done
  local got_major got_minor
  got_major=$(symbol_int "$obj" plugin_want_major) || got_major="?"
  got_minor=$(symbol_int "$obj" plugin_want_minor) || got_minor="?"
  [ "$got_major.$got_minor" = "$major.$minor" ] ||
    problems+=("plugin_want_major.minor is $got_major.$got_minor, but the headers are $major.$minor")
  [ ${#problems[@]} -eq 0 ] || { printf '%s\n' "${problems[@]}"; return 1; }
}

# Compiles everything against one set of headers.
check_version() { # LABEL DEST-OR-EMPTY
  local label="$1" dest="$2" rel obj log n=0
  if ! cflags_for "$dest"; then
    for rel in "${runtime_sources[@]}" "${rule_files[@]}"; do report FAIL "$label" "$rel" "$fetch_error"; done
    return
  fi
  label="$ws_version ($label)"
  read -r -a cf <<<"$ws_cflags"
  mkdir -p "$work/obj"
  for rel in "${runtime_sources[@]}"; do
    obj="$work/obj/$(basename "$rel" .cpp).o"
    if log=$("$cxx" "${flags[@]}" "${cf[@]}" -c "$root/$rel" -o "$obj" 2>&1); then
      report PASS "$label" "$rel"
    else
      report FAIL "$label" "$rel" "$log"
    fi
  done
  for rel in "${rule_files[@]}"; do
    n=$((n + 1))
    if [ -n "${gen_error[$rel]:-}" ]; then report FAIL "$label" "$rel" "${gen_error[$rel]}"; continue; fi
    obj="$work/obj/plugin-$n.o"
    if ! log=$("$cxx" "${flags[@]}" "${cf[@]}" -c "${generated[$rel]}" -o "$obj" 2>&1); then
      report FAIL "$label" "$rel" "$log"
    elif ! log=$(check_plugin_object "$obj" "$ws_version"); then
      report FAIL "$label" "$rel" "$log"
    else
      report PASS "$label" "$rel"
    fi
  done
  rm -rf "$work/obj"
}

# The system's headers first: they need no network.
check_version system ""

mirror="${DISSGEN_DEBIAN_MIRROR:-$(machine_mirror)}"
if [ -z "$mirror" ]; then
  skip_reason="no Debian mirror found in /etc/apt/sources.list or /etc/apt/sources.list.d (set DISSGEN_DEBIAN_MIRROR)"
else
  setup_apt "$mirror"
  fetch_indexes "$mirror"
  status=$?
  if [ $status -eq 2 ]; then
    for suite in $suites; do
      for rel in "${runtime_sources[@]}" "${rule_files[@]}"; do report FAIL "$suite" "$rel" "apt-get update failed"; done
    done
  elif [ $status -eq 0 ]; then
    for suite in $suites; do
      if fetch_suite "$suite"; then
        check_version "$suite" "$work/ws-$suite"
      elif grep -Eq "$network_trouble" "$work/debs-$suite/download.log"; then
        skip_reason="the Debian archive at $mirror cannot be reached (downloading $suite's packages)"
      else
        for rel in "${runtime_sources[@]}" "${rule_files[@]}"; do report FAIL "$suite" "$rel" "$fetch_error"; done
      fi
    done
  fi
fi

echo "($(( $(date +%s) - started ))s)"
echo "multiversion: $passed passed, $failed failed"
[ "$failed" -eq 0 ] || exit 1
if [ -n "$skip_reason" ]; then
  echo "SKIPPED: $skip_reason"
  exit 77
fi
exit 0
