#!/usr/bin/env bash
# The whole test suite under AddressSanitizer (with LeakSanitizer) and UndefinedBehaviorSanitizer
# (issue #15). Builds build-asan/ (RelWithDebInfo, -DGDSR_SANITIZE=address,undefined, every
# finding fatal: -fno-sanitize-recover=all, halt_on_error=1), runs every ctest test there and
# exits non-zero on a build failure, a failed test or any sanitizer report, including one from
# a gdsr process that a test runs (ASan/LSan reports go to files in build-asan/sanitizer-logs/,
# UBSan's are searched in the tests' whole output; all printed at the end). Last line: a
# one-line summary.
#
#   bash scripts/sanitize.sh              # build, then the whole suite
#   bash scripts/sanitize.sh -R 'cli: '   # extra ctest arguments narrow every pass
# Environment: GDSR_ASAN_BUILD (folder, default build-asan), GDSR_JOBS (build jobs, default 1).
# Measured on the shared 2-core machine, at nice 19: 50 min of build (one job), 15 min of tests.
set -uo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
build=${GDSR_ASAN_BUILD:-build-asan}
t0=$(date +%s)

# MPI on when Debian's OpenMPI is installed, as in CI (the two-rank training test then runs).
mpi=OFF
if command -v mpicxx >/dev/null 2>&1 && command -v mpirun >/dev/null 2>&1; then mpi=ON; fi
# No benchmarks: they are not tests, and would add build time.
if ! cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGDSR_SANITIZE=address,undefined \
     -DGDSR_MPI=$mpi -DCMAKE_DISABLE_FIND_PACKAGE_benchmark=ON -DCMAKE_CXX_FLAGS=-fno-sanitize-recover=all; then
  echo "sanitize: FAILED: cmake configure"
  exit 2
fi
if ! OMP_NUM_THREADS=1 cmake --build "$build" -j"${GDSR_JOBS:-1}"; then
  echo "sanitize: FAILED: build"
  exit 2
fi
t1=$(date +%s)

logs="$root/$build/sanitizer-logs"
rm -rf "$logs" && mkdir -p "$logs"
# Every sanitizer report ends its process with exit code 99 (a gdsr run by a test then fails
# the test: the CLI tests check for 0, or 1 with the error line). ASan and LSan reports also go
# to files in $logs, seen even when a test keeps a child's stderr to itself. GCC's UBSan is a
# library of its own that ignores log_path when ASan is loaded: its reports go to stderr (of
# the test, or of the gdsr it runs). So every test's whole output is kept (ctest -O) and
# searched for reports too.
common="log_path=$logs/report:exitcode=99:print_suppressions=0"
export ASAN_OPTIONS="$common:detect_leaks=1:halt_on_error=1:abort_on_error=0:check_initialization_order=1:strict_init_order=1"
export UBSAN_OPTIONS="$common:halt_on_error=1:print_stacktrace=1"
# Suppressions only for leaks inside third-party libraries, each with its reason in the file.
export LSAN_OPTIONS="suppressions=$root/scripts/lsan.supp"
if command -v llvm-symbolizer >/dev/null 2>&1; then export ASAN_SYMBOLIZER_PATH=$(command -v llvm-symbolizer); fi
# One OpenMP thread per test (as scripts/test.sh).
export OMP_NUM_THREADS=1
# Per-test time limit 3600 s instead of scripts/test.sh's 900 s: ASan + UBSan make the code
# 2-4x slower. Only a guard against a hang: the slowest sanitized test took 87 s.
timeout=3600

# Tests run in passes of their own with a changed environment, each with its reason (never
# silently); the main pass leaves them out. Three arrays, one entry per pass.
sp_re=() sp_env=() sp_why=()
# LeakSanitizer stops the world with ptrace, which fails when the process is already traced:
# under strace every gdsr run would end in "LeakSanitizer has encountered a fatal error".
sp_re+=('cli writes: (a dataset replace|infer) killed at each rename')
sp_env+=("ASAN_OPTIONS=$ASAN_OPTIONS:detect_leaks=0")
sp_why+=("gdsr runs under strace (ptrace), where LeakSanitizer cannot run: leak checking off, ASan+UBSan on")
# OpenMPI's libraries have no frame pointers and unload their plugins in MPI_Finalize, so its
# leaks at exit have one-frame stacks in "<unknown module>" that no suppression can name.
sp_re+=('cli train mpi: ')
sp_env+=("ASAN_OPTIONS=$ASAN_OPTIONS:fast_unwind_on_malloc=0 OMPI_MCA_mca_base_component_disable_dlclose=1")
sp_why+=("OpenMPI's leaks get whole stacks (slow unwinding, plugins kept loaded) so that scripts/lsan.supp names them")
# Tests left out entirely: "regex|reason" (none at present).
excluded=()

# ctest's numbers of the tests a filter selects (extra arguments narrow every pass).
ids() { (cd "$build" && ctest -N "$@") | sed -nE 's/^ *Test +#([0-9]+): .*/\1/p' | sort; }
exclude_re='^$'
for e in "${excluded[@]+"${excluded[@]}"}"; do
  exclude_re="$exclude_re|${e%%|*}"
  echo "sanitize: excluded: ${e%%|*}: ${e#*|}"
done
for i in "${!sp_re[@]}"; do exclude_re="$exclude_re|${sp_re[$i]}"; done

logs_ctest=()
run_pass() {  # run_pass LOG "ENV ASSIGNMENTS" CTEST ARGS...
  local log=$1 envs=$2
  shift 2
  logs_ctest+=("$log")
  # shellcheck disable=SC2086
  (cd "$build" && env $envs ctest -j1 --timeout $timeout --output-on-failure -O "${log%.log}.full.log" "$@") 2>&1 |
    tee "$log"
}
run_pass "$root/$build/ctest-sanitize.log" "" -E "$exclude_re" "$@"
for i in "${!sp_re[@]}"; do
  sel=$(comm -12 <(ids -R "${sp_re[$i]}") <(ids "$@") | sort -n | paste -sd, -)
  [ -n "$sel" ] || continue
  echo "sanitize: own pass: ${sp_re[$i]}: ${sp_why[$i]}"
  run_pass "$root/$build/ctest-sanitize-pass$((i + 2)).log" "${sp_env[$i]}" -I "0,0,0,$sel"
done
t2=$(date +%s)

# Counts from ctest's per-test lines ("Test #n: name ....   Passed   1.23 sec").
count() { cat "${logs_ctest[@]}" | grep -E '^ *[0-9]+/[0-9]+ Test +#[0-9]+: ' | grep -cE "$1"; }
ran=$(count '.')
passed=$(count ' Passed +[0-9.]+ sec')
skipped=$(count '\*\*\*Skipped|Not Run')
failed=$((ran - passed - skipped))
reports=$(find "$logs" -type f | wc -l)
if [ "$reports" -gt 0 ]; then
  echo "sanitize: sanitizer reports ($reports):"
  for f in "$logs"/*; do
    echo "==== $f"
    cat "$f"
  done
fi
# Reports printed to stderr (UBSan's, and any that a test printed from a child's stderr).
marks='runtime error: |ERROR: (AddressSanitizer|LeakSanitizer|UndefinedBehaviorSanitizer)|LeakSanitizer has encountered'
printed=$(for l in "${logs_ctest[@]}"; do grep -E "$marks" "${l%.log}.full.log"; done | grep -cv '^$')
if [ "$printed" -gt 0 ]; then
  echo "sanitize: sanitizer reports in test output ($printed lines):"
  for l in "${logs_ctest[@]}"; do grep -nE "$marks" "${l%.log}.full.log" | sed "s|^|$(basename "${l%.log}").full.log:|"; done
  reports=$((reports + printed))
fi
status=0
[ "$failed" -eq 0 ] && [ "$reports" -eq 0 ] && [ "$ran" -gt 0 ] || status=1
echo "sanitize: $([ $status -eq 0 ] && echo OK || echo FAILED): $ran tests run, $passed passed, $failed failed," \
  "$skipped skipped, ${#excluded[@]} excluded; $reports sanitizer reports;" \
  "build $((t1 - t0)) s, tests $((t2 - t1)) s (logs: $build/ctest-sanitize*.log, $build/sanitizer-logs/)"
exit $status
