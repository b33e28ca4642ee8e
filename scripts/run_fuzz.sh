#!/usr/bin/env bash
# Runs each libFuzzer harness of a fuzz build tree for SECONDS: scripts/run_fuzz.sh BUILD SECONDS
# [HARNESS...]. Seeds come from test/fuzz/corpus/<harness>/ (read only); what the run finds goes
# to BUILD/corpus/<harness>/ (kept between runs), a crashing input to BUILD/artifacts/<harness>/.
# Each run resumes from BUILD/corpus/<harness>/, so a campaign of hours can be run in parts
# (make fuzz-long). Prints executions, seconds, exec/s, coverage (edges, features) and corpus
# size per harness; exit status non-zero if any harness failed. FUZZ_JOBS (default 1) harnesses
# run at once.
set -uo pipefail
build=${1:?usage: run_fuzz.sh BUILD_DIR SECONDS [HARNESS...]}
seconds=${2:?usage: run_fuzz.sh BUILD_DIR SECONDS [HARNESS...]}
shift 2
root=$(cd "$(dirname "$0")/.." && pwd)
harnesses=("$@")
[ ${#harnesses[@]} -eq 0 ] && harnesses=(fuzz_map_load fuzz_carmen fuzz_integrate fuzz_node fuzz_fleet fuzz_site)

# Leaks count as findings; UBSan already aborts (-fno-sanitize-recover=all).
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:allocator_may_return_null=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
jobs=${FUZZ_JOBS:-1}

# One harness: its run, then its summary line in BUILD/summary_<harness>.txt; status 1 if it failed.
run_one() {
  local h=$1
  local bin=$build/fuzz/$h
  local seeds=$root/test/fuzz/corpus/$h
  local work=$build/corpus/$h
  local artifacts=$build/artifacts/$h/
  local log=$build/fuzz_$h.log
  mkdir -p "$work" "$artifacts"
  # -timeout: one input taking longer is a hang finding; -rss_limit_mb / -malloc_limit_mb: one
  # input needing more memory is a finding too (the machine is shared).
  "$bin" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -malloc_limit_mb=1024 \
    -print_final_stats=1 -artifact_prefix="$artifacts" "$work" "$seeds" >"$log" 2>&1
  local status=$?
  local execs rate secs last cov ft corp
  execs=$(grep -Eo 'stat::number_of_executed_units: *[0-9]+' "$log" | grep -Eo '[0-9]+$' | tail -1)
  rate=$(grep -Eo 'stat::average_exec_per_sec: *[0-9]+' "$log" | grep -Eo '[0-9]+$' | tail -1)
  secs=$(grep -Eo 'Done [0-9]+ runs in [0-9]+ second' "$log" | grep -Eo '[0-9]+ second' | grep -Eo '[0-9]+' | tail -1)
  # Coverage of the last status line: edges (cov), features (ft), corpus entries (corp).
  last=$(grep -E '^#[0-9]+' "$log" | grep -E 'cov: ' | tail -1)
  cov=$(grep -Eo 'cov: [0-9]+' <<<"$last" | grep -Eo '[0-9]+')
  ft=$(grep -Eo 'ft: [0-9]+' <<<"$last" | grep -Eo '[0-9]+')
  corp=$(grep -Eo 'corp: [0-9]+' <<<"$last" | grep -Eo '[0-9]+')
  if [ "$status" -ne 0 ]; then
    echo "fuzz: $h FAILED (status $status); log $log, input in $artifacts:" >&2
    grep -E 'ERROR|runtime error|oracle failed|SUMMARY|Test unit written' "$log" | head -20 >&2
  fi
  printf '%-16s %s  %12s executions  %6s s  %8s exec/s  cov %6s  ft %7s  corpus %6s\n' \
    "$h" "$([ "$status" -eq 0 ] && echo clean || echo FAILED)" "${execs:-?}" "${secs:-?}" \
    "${rate:-?}" "${cov:-?}" "${ft:-?}" "${corp:-?}" >"$build/summary_$h.txt"
  [ "$status" -eq 0 ]
}

# FUZZ_JOBS harnesses at once (each is one process, so on as many cores each runs as fast as alone).
pids=()
for h in "${harnesses[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do sleep 1; done
  run_one "$h" &
  pids+=($!)
done
failed=0
for p in "${pids[@]}"; do wait "$p" || failed=1; done
for h in "${harnesses[@]}"; do cat "$build/summary_$h.txt"; done
exit "$failed"
