#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The real Wireshark GUI with a dissgen plugin, headless: install the EtherCAT
# plugin for an unprivileged user in a temporary HOME, start Wireshark (Qt)
# under Xvfb on samples/ethercat-demo.pcap, go to a frame, expand the rules'
# tree, save a screenshot, and check that Wireshark started, loaded the plugin
# with no error dialog and no loader message, and exits 0 when asked to quit.
# With --statistics ENTRY (and --rules, --capture), open that entry of the
# Statistics menu instead (e.g. "ENIPR cycles", the statistics tree of a rule
# file's <cycles>), check its window shows rows and save a screenshot of it.
#
#   tests/gui/screenshot.sh [--dissgen PATH] [--out FILE.png] [--frame N] [--keep]
#                           [--also-install RULES.xml] [--ctest]
#                           [--rules RULES.xml] [--capture FILE] [--statistics ENTRY]
#
# Default --dissgen: build/bin/dissgen, else dissgen on PATH. Default --out: a
# file in the temporary folder (docs/images/wireshark-ethercat.png is made with
# --out docs/images/wireshark-ethercat.png). Installs wireshark-qt, xvfb,
# xdotool, x11-utils and fonts-dejavu-core with apt-get when they are missing
# (as root; otherwise prints SKIPPED and exits 77); with --ctest (how ctest runs
# it) only in CI (CI set): a developer's machine is not changed by a test run.
# Prints "N passed, N failed".
# --also-install installs one more rule file for the user first, e.g. one whose
# protocol names clash, to see (and check that we detect) Wireshark's error dialog.
set -u

here=$(cd "$(dirname "$0")" && pwd)
source_dir=$(cd "$here/../.." && pwd)
dissgen="" out="" frame=8 keep=0 also="" from_ctest=0 statistics=""
capture="$source_dir/samples/ethercat-demo.pcap"
rules="$source_dir/rules/ethercat.xml"
while [ $# -gt 0 ]; do
  case "$1" in
    --dissgen) dissgen="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --frame) frame="$2"; shift 2 ;;
    --keep) keep=1; shift ;;
    --ctest) from_ctest=1; shift ;;
    --also-install) also=$(readlink -f "$2"); shift 2 ;;
    --rules) rules=$(readlink -f "$2"); shift 2 ;;
    --capture) capture=$(readlink -f "$2"); shift 2 ;;
    --statistics) statistics="$2"; shift 2 ;;
    *) echo "usage: $0 [--dissgen PATH] [--out FILE.png] [--frame N] [--keep] [--also-install RULES]" \
            "[--rules RULES.xml] [--capture FILE] [--statistics ENTRY]" >&2
       exit 2 ;;
  esac
done
if [ -z "$dissgen" ]; then
  if [ -x "$source_dir/build/bin/dissgen" ]; then dissgen="$source_dir/build/bin/dissgen"
  else dissgen=$(command -v dissgen || true); fi
fi
[ -n "$dissgen" ] && [ -x "$dissgen" ] || { echo "SKIPPED: no dissgen (build it, or pass --dissgen)"; exit 77; }
dissgen=$(readlink -f "$dissgen")
[ -r "$capture" ] || { echo "SKIPPED: no capture $capture"; exit 77; }
capture_name=$(basename "$capture")
plugin="dissgen_$(basename "$rules" .xml).so"
t0=$(date +%s)

# --- tools -------------------------------------------------------------------
missing=()
command -v wireshark >/dev/null || missing+=(wireshark-qt)
command -v Xvfb >/dev/null || missing+=(xvfb)
command -v xdotool >/dev/null || missing+=(xdotool)
command -v xwininfo >/dev/null || missing+=(x11-utils)
fc-list 2>/dev/null | grep -qi dejavu || missing+=(fonts-dejavu-core)
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -ne 0 ] || { [ "$from_ctest" = 1 ] && [ -z "${CI:-}" ]; }; then
    echo "SKIPPED: needs ${missing[*]} (apt-get install them, or run tests/gui/screenshot.sh as root)"
    exit 77
  fi
  echo "installing: ${missing[*]}"
  if ! { apt-get install -y -q --no-install-recommends "${missing[@]}" >/tmp/dissgen-gui-apt.log 2>&1 ||
         { apt-get update -q >/dev/null 2>&1 &&
           apt-get install -y -q --no-install-recommends "${missing[@]}" >/tmp/dissgen-gui-apt.log 2>&1; }; }
  then
    echo "SKIPPED: could not install ${missing[*]} (see /tmp/dissgen-gui-apt.log)"
    exit 77
  fi
  echo "installed in $(( $(date +%s) - t0 ))s"
fi
for tool in setpriv python3 tshark; do
  command -v "$tool" >/dev/null || { echo "SKIPPED: $tool is not installed"; exit 77; }
done

passed=0 failed=0
ok() { echo "ok: $1"; passed=$((passed + 1)); }
not_ok() { echo "FAILED: $1"; failed=$((failed + 1)); }

work=$(mktemp -d /tmp/dissgen-gui.XXXXXX)
chmod 755 "$work"
home="$work/home"
mkdir -p "$home/run" "$home/tmp" "$work/fb"
chmod 700 "$home/run"
cp "$capture" "$home/$capture_name"
xvfb_pid="" ws_pid=""
cleanup() {
  [ -n "$ws_pid" ] && kill "$ws_pid" 2>/dev/null
  [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null
  wait 2>/dev/null
  [ "$keep" = 1 ] && echo "(kept $work)" || rm -rf "$work"
}
trap cleanup EXIT

# Wireshark run as root ignores per-user plugins: everything runs as uid 65534
# when this script is root; otherwise as the current user.
if [ "$(id -u)" -eq 0 ]; then
  chown -R 65534:65534 "$home"
  as_user() { setpriv --reuid=65534 --regid=65534 --clear-groups "$@"; }
else
  as_user() { "$@"; }
fi
user_env=(env -i HOME="$home" PATH=/usr/bin:/bin LANG=C.UTF-8 LC_ALL=C.UTF-8 TZ=UTC TMPDIR="$home/tmp"
          XDG_RUNTIME_DIR="$home/run" XDG_CONFIG_HOME="$home/.config")

# What that user runs and reads is staged in $work: the checkout (build/bin/dissgen,
# the rules, the runtime its share/dissgen links to) may sit in a private folder.
mkdir -p "$work/prefix/bin" "$work/prefix/share" "$work/rules"
cp "$dissgen" "$work/prefix/bin/dissgen"
cp -rL "$(dirname "$dissgen")/../share/dissgen" "$work/prefix/share/dissgen"
cp "$rules" "$work/rules/"
dissgen="$work/prefix/bin/dissgen" rules="$work/rules/$(basename "$rules")"
chmod -R a+rX "$work/prefix" "$work/rules"

# --- the plugin, for that user ---------------------------------------------------
if [ -n "$also" ]; then
  cp "$also" "$work/$(basename "$also")"
  chmod 644 "$work/$(basename "$also")"
  as_user "${user_env[@]}" "$dissgen" install "$work/$(basename "$also")" 2>&1 | sed 's/^/(also) /'
fi
if as_user "${user_env[@]}" "$dissgen" install "$rules" >"$work/install.out" 2>&1; then
  ok "$(head -1 "$work/install.out")"
else
  not_ok "dissgen install: $(cat "$work/install.out")"
  echo "$passed passed, $failed failed"; exit 1
fi
as_user "${user_env[@]}" tshark -G plugins >"$work/plugins" 2>&1
grep -q "$plugin" "$work/plugins" && ok "tshark (same user and HOME) lists $plugin" ||
  not_ok "tshark does not list the plugin: $(cat "$work/plugins")"

# --- X server --------------------------------------------------------------------
# -displayfd: Xvfb picks a free display and tells us; -fbdir: the screen is an XWD file.
# -noreset: by default the server resets when its last client leaves (the xdpyinfo
# probe below), and a Wireshark connecting during that reset fails to start (seen in CI).
Xvfb -displayfd 3 -screen 0 1280x800x24 -fbdir "$work/fb" -nolisten tcp -ac -noreset 3>"$work/display" \
  >"$work/xvfb.log" 2>&1 &
xvfb_pid=$!
for _ in $(seq 100); do [ -s "$work/display" ] && break; sleep 0.1; done
if [ ! -s "$work/display" ]; then
  not_ok "Xvfb did not start: $(cat "$work/xvfb.log")"; echo "$passed passed, $failed failed"; exit 1
fi
export DISPLAY=":$(head -1 "$work/display")"
user_env+=(DISPLAY="$DISPLAY")
for _ in $(seq 50); do   # reachable by the user who runs Wireshark
  as_user "${user_env[@]}" xdpyinfo >/dev/null 2>&1 && break
  sleep 0.2
done

# --- Wireshark ------------------------------------------------------------------
# Window and pane sizes (Wireshark's "recent" files), -o gui.layout_type:1 (packet
# list, details and bytes stacked), -g: go to the frame. The same picture everywhere.
width=1100 height=760 list_height=180 details_height=370
mkdir -p "$home/.config/wireshark"
printf 'gui.geometry_main_x: 0\ngui.geometry_main_y: 0\ngui.geometry_main_width: %d\ngui.geometry_main_height: %d\ngui.geometry_main_maximized: FALSE\n' \
  "$width" "$height" >"$home/.config/wireshark/recent_common"
printf 'gui.geometry_main_upper_pane: %d\ngui.geometry_main_lower_pane: %d\n' "$list_height" "$details_height" \
  >"$home/.config/wireshark/recent"
[ "$(id -u)" -eq 0 ] && chown -R 65534:65534 "$home/.config"
start_wireshark() {
  as_user "${user_env[@]}" wireshark -r "$home/$capture_name" -g "$frame" -o gui.layout_type:1 \
    >"$work/wireshark.out" 2>"$work/wireshark.err" &
  ws_pid=$!
}
start_wireshark

# Wireshark's visible top-level windows, one per line: ID "TITLE" WxH (not the
# 1x1 group leader or the 3x3 selection owner).
windows() {
  local w geometry
  for w in $(xdotool search --onlyvisible --class wireshark 2>/dev/null); do
    geometry=$(xwininfo -id "$w" 2>/dev/null | awk '/Width:/ {w=$2} /Height:/ {h=$2} END {print w "x" h}')
    case "$geometry" in 1x1|3x3|x) continue ;; esac
    echo "$w \"$(xdotool getwindowname "$w" 2>/dev/null)\" $geometry"
  done
}
# Any window but the main one (titled "The Wireshark Network Analyzer" until the
# file is read, then after the file) is a dialog: an error, a warning.
dialogs() { windows | grep -vF " \"$capture_name" | grep -v " \"The Wireshark Network Analyzer\"" ; }
save_screen() { python3 "$here/xwd2png.py" "$work/fb/Xvfb_screen0" "$1" && echo "    (screen saved as $1)"; }

main="" found=""
for _ in $(seq 120); do
  main=$(windows | awk -v t=" \"$capture_name" 'index($0, t) {print $1; exit}')
  found=$(dialogs)
  [ -n "$main" ] || [ -n "$found" ] && break
  if ! kill -0 "$ws_pid" 2>/dev/null; then
    # Not reaching the X server is the test machine's problem, not the plugin's:
    # one more try once the server answers again.
    grep -q "could not connect to display" "$work/wireshark.err" && [ -z "${retried:-}" ] || break
    retried=1
    echo "    (Wireshark could not reach $DISPLAY; starting it again)"
    as_user "${user_env[@]}" xdpyinfo >/dev/null 2>&1 || sleep 1
    start_wireshark
  fi
  sleep 0.5
done
sleep 3   # reading the file and going to the frame; a dialog may still come
found=$(dialogs)
if [ -n "$found" ]; then
  not_ok "Wireshark shows a dialog: $(echo "$found" | cut -d' ' -f2- | tr '\n' ' ')"
  save_screen "${out:-$work/screen.png}"
  sed 's/^/    stderr: /' "$work/wireshark.err"
  echo "$passed passed, $failed failed"; exit 1
fi
ok "no dialog window"
if [ -n "$main" ]; then
  ok "Wireshark's main window shows $capture_name ($(( $(date +%s) - t0 ))s)"
else
  not_ok "no Wireshark main window with the capture; windows: $(windows | tr '\n' ' ') stderr: $(cat "$work/wireshark.err")"
  echo "$passed passed, $failed failed"; exit 1
fi

# Wireshark's Statistics menu has no search: the entry is found by opening the
# menu (Alt+S), going down k items and taking it, k first where Debian's
# Wireshark 4.0 puts a stats tree plugin, then around it; a wrong item's
# dialog is closed again. Prints the entry's window id.
open_statistics_entry() {
  local k w d
  for k in 26 27 25 28 24 29 23 30 31 32 33 34 35 36 37 38 39 40 22 21 20; do
    xdotool windowfocus --sync "$main" 2>/dev/null || xdotool windowfocus "$main"
    xdotool key Escape Escape
    sleep 0.3
    xdotool key alt+s
    sleep 0.7
    xdotool key --repeat "$k" --delay 20 Down
    xdotool key Return
    for _ in $(seq 12); do   # a window comes, or (a submenu, a separator) none
      sleep 0.5
      w=$(xdotool search --onlyvisible --name " $statistics " 2>/dev/null | head -1)
      [ -n "$w" ] || [ -n "$(dialogs)" ] && break
    done
    if [ -n "$w" ]; then echo "$w"; return 0; fi
    for d in $(dialogs | cut -d' ' -f1); do   # another item's dialog
      xdotool windowfocus "$d" 2>/dev/null; xdotool key Escape; sleep 0.5
    done
  done
  return 1
}

# The rows "Cycle N WHAT  VALUE" of a statistics tree's text (tshark -z ...,tree,
# or the dialog's Save as... in plain text), sorted.
tree_rows() { sed -n 's/^ *\(Cycle [0-9][0-9]* [^ ].*[^ ]\)  *\([0-9][0-9]*\) .*$/\1 = \2/p' "$1" | sort; }

if [ -n "$statistics" ]; then
  # --- the Statistics menu entry -------------------------------------------------------
  if dialog=$(open_statistics_entry); then
    ok "Statistics > $statistics opens its window ($(xdotool getwindowname "$dialog"))"
  else
    not_ok "no entry '$statistics' in the Statistics menu; windows: $(windows | tr '\n' ' ')"
    save_screen "${out:-$work/screen.png}"
    echo "$passed passed, $failed failed"; exit 1
  fi
  xdotool mousemove $((width + 100)) $((height + 20))
  sleep 2   # the tree is filled once the capture is tapped again
  eval "$(xdotool getwindowgeometry --shell "$dialog")"   # X Y WIDTH HEIGHT
  png="${out:-$work/statistics.png}"
  mkdir -p "$(dirname "$png")"
  python3 "$here/xwd2png.py" "$work/fb/Xvfb_screen0" "$png" --crop "$X,$Y,$WIDTH,$HEIGHT" &&
    ok "screenshot $png ($(stat -c %s "$png") bytes, ${WIDTH}x${HEIGHT})" || not_ok "screenshot failed"
  size=$(stat -c %s "$png" 2>/dev/null || echo 0)
  [ "$size" -gt 10000 ] && [ "$size" -lt 300000 ] && ok "screenshot size $size bytes (10 KB .. 300 KB)" ||
    not_ok "screenshot size $size bytes"
  # What the window shows, through its Save as... button (bottom right, left of
  # Close) as plain text, against tshark -2 -z TREE,tree of the same capture.
  tree=$(echo "$statistics" | awk '{print tolower($1) "." $2}')
  as_user "${user_env[@]}" tshark -2 -r "$home/$capture_name" -q -z "$tree,tree" >"$work/tshark-tree.txt" 2>&1
  xdotool mousemove $((X + WIDTH - 144)) $((Y + HEIGHT - 24)) click 1
  for _ in $(seq 20); do   # the file dialog
    sleep 0.5
    dialogs | grep -qv "^$dialog " && break
  done
  sleep 0.5
  xdotool type --delay 20 "$home/shown.txt"
  xdotool key Return
  for _ in $(seq 20); do [ -s "$home/shown.txt" ] && break; sleep 0.5; done
  tree_rows "$home/shown.txt" >"$work/shown.rows"
  tree_rows "$work/tshark-tree.txt" >"$work/tshark.rows"
  rows=$(wc -l <"$work/shown.rows")
  if [ "$rows" -gt 0 ] && cmp -s "$work/shown.rows" "$work/tshark.rows"; then
    ok "the window shows $rows rows, each as tshark -2 -z $tree,tree gives it"
  else
    not_ok "the window's rows ($rows) differ from tshark -2 -z $tree,tree: $(diff "$work/shown.rows" \
      "$work/tshark.rows" | head -5 | tr '\n' ' ')"
  fi
  xdotool windowfocus "$dialog" 2>/dev/null; xdotool key Escape
  sleep 1
else
  # A click in the packet details pane gives it the keyboard; select its third
  # top-level item (Frame, Ethernet II, EtherCAT) and expand it with all its
  # subtrees (Shift+Right, View > Expand Subtrees).
  xdotool windowfocus --sync "$main" 2>/dev/null || xdotool windowfocus "$main"
  sleep 0.5
  xdotool mousemove --window "$main" $((width / 2)) $((90 + list_height + details_height / 2)) click 1
  sleep 0.5
  xdotool key --delay 300 Home Down Down shift+Right
  xdotool mousemove $((width + 100)) $((height + 20))   # the pointer off the window
  sleep 1.5

  # --- screenshot --------------------------------------------------------------------
  eval "$(xdotool getwindowgeometry --shell "$main")"   # X Y WIDTH HEIGHT
  png="${out:-$work/wireshark-ethercat.png}"
  mkdir -p "$(dirname "$png")"
  if python3 "$here/xwd2png.py" "$work/fb/Xvfb_screen0" "$png" --crop "$X,$Y,$WIDTH,$HEIGHT"; then
    ok "screenshot $png ($(stat -c %s "$png") bytes, ${WIDTH}x${HEIGHT})"
  else
    not_ok "screenshot failed"
  fi
  size=$(stat -c %s "$png" 2>/dev/null || echo 0)
  [ "$size" -gt 10000 ] && [ "$size" -lt 300000 ] && ok "screenshot size $size bytes (10 KB .. 300 KB)" ||
    not_ok "screenshot size $size bytes"
fi

found=$(dialogs)
[ -z "$found" ] && ok "still no dialog window" || not_ok "dialog windows: $found"

# --- quit ---------------------------------------------------------------------------
xdotool windowfocus "$main" 2>/dev/null
xdotool key ctrl+q
status=""
for _ in $(seq 60); do
  if ! kill -0 "$ws_pid" 2>/dev/null; then wait "$ws_pid"; status=$?; break; fi
  sleep 0.5
done
if [ -z "$status" ]; then
  not_ok "Wireshark did not exit within 30 s of Ctrl+Q"
else
  ws_pid=""
  [ "$status" -eq 0 ] && ok "Wireshark exited 0 on Ctrl+Q" || not_ok "Wireshark exited $status on Ctrl+Q"
fi

# Wireshark's stderr: no plugin loader message, nothing about dissgen or our protocol.
if grep -Eiq "plugin|symbol|compiled for|\.so\b|couldn't load|undefined|dissgen|ecatr|not loaded|error|critical" \
     "$work/wireshark.err"; then
  not_ok "Wireshark's stderr: $(cat "$work/wireshark.err")"
else
  ok "no loader or plugin message on Wireshark's stderr ($(wc -l <"$work/wireshark.err") other lines)"
fi
sed 's/^/    stderr: /' "$work/wireshark.err"

echo "$passed passed, $failed failed ($(( $(date +%s) - t0 ))s)"
[ "$failed" -eq 0 ]
