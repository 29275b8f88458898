#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Builds the libFuzzer target for the rule-file, ESI and network front ends
# (clang, with AddressSanitizer and UndefinedBehaviorSanitizer) and runs it for
# a bounded time, seeded with every rule, ESI and network file of the tests. The corpus lives in a
# temporary folder: nothing is written into the source tree.
#
#   tests/fuzz/run_fuzz.sh [SECONDS]      (default: $FUZZ_SECONDS or 180)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
src=$(cd "$here/../.." && pwd)
seconds=${1:-${FUZZ_SECONDS:-180}}

if ! command -v clang++ >/dev/null || ! clang++ -fsanitize=fuzzer -x c++ -o /dev/null - <<<'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long){return 0;}' 2>/dev/null; then
  echo "SKIPPED: clang++ with libFuzzer is not installed (apt-get install clang libclang-rt-14-dev)"
  exit 77
fi

work=$(mktemp -d /tmp/dissgen-fuzz-XXXXXX)
trap 'rm -rf "$work"' EXIT
# Every generator source but main.cpp (libFuzzer brings its own main), so a
# new pipeline stage is fuzzed without being listed here.
generator_sources=()
for f in "$src"/generator/*.cpp "$src"/generator/ethercat/*.cpp; do
  [ "$(basename "$f")" = main.cpp ] || generator_sources+=("$f")
done
# runtime_list_text.h: the header CMake configures from plugin_runtime/runtime.list
# (generator/runtime_list_text.h.in), made the same way for this build.
python3 - "$src/generator/runtime_list_text.h.in" "$src/plugin_runtime/runtime.list" \
  "$work/runtime_list_text.h" <<'END'
import sys
template, listing, out = sys.argv[1:]
text = open(template, encoding="utf-8").read().replace("@runtime_list_text@", open(listing, encoding="utf-8").read())
open(out, "w", encoding="utf-8").write(text)
END
clang++ -std=c++17 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
  -I"$src/generator" -I"$work" $(pkg-config --cflags libxml-2.0) \
  "$here/fuzz_rules.cpp" "${generator_sources[@]}" \
  $(pkg-config --libs libxml-2.0) -o "$work/fuzz_rules"

mkdir -p "$work/corpus"
n=0
for f in "$src"/rules/*.xml "$src"/tests/rules/*.xml "$src"/tests/rules_ok/*.xml "$src"/tests/rules_err/*.xml \
         "$src"/tests/esi_ok/*.xml "$src"/tests/esi_err/*.xml "$src"/tests/network/*.xml "$src"/tests/network_err/*.xml; do
  [ -f "$f" ] || continue
  cp "$f" "$work/corpus/seed_$n.xml"
  n=$((n + 1))
done
echo "fuzz: $n seed files, $seconds seconds"

# -max_len keeps inputs near rule-file size; -timeout flags a hang of 30 s on
# one input. The sanitizers make the front end some ten times slower: a file
# that spends the whole XPath budget (20 million steps, about 1 s natively)
# takes 10 s here, a cost the budget bounds, not a hang.
# The input that failed is kept (artifacts/ beside the run) and its head
# printed: a failure on a CI machine can then be replayed with
#   fuzz_rules artifacts/crash-...
artifacts="$PWD/fuzz-artifacts"
mkdir -p "$artifacts"
"$work/fuzz_rules" "$work/corpus" -max_total_time="$seconds" -max_len=16384 -timeout=30 \
  -rss_limit_mb=2048 -print_final_stats=1 -dict="$here/rules.dict" -artifact_prefix="$artifacts/" 2>"$work/log" || {
  status=$?
  tail -60 "$work/log"
  for a in "$artifacts"/*; do
    [ -f "$a" ] || continue
    echo "fuzz: failing input $a ($(wc -c <"$a") bytes), first 40 lines:"
    head -c 4000 "$a" | head -40
    echo
  done
  echo "fuzz: FAILED (exit $status)"
  echo "0 passed, 1 failed"
  exit 1
}
grep -E "stat::number_of_executed_units|stat::peak_rss_mb|stat::new_units_added" "$work/log" || true
echo "fuzz: no crash, leak, hang or sanitizer report"
echo "1 passed, 0 failed"
