#!/usr/bin/env bash
# bench/smoke, the step `scripts/test` runs after the suite, fails when one bench script
# fails, and names it: scripts found in a scratch folder (--scripts-from) stand for
# bench/'s, one passing and one exiting 3. Also: a benchmark program that is not built
# fails the step, and scripts/test ends with the step.
#
#   tests/bench/smoke_step_test.sh SOURCE_DIR BUILD_DIR     (ctest BenchSmoke.AFailingScriptFailsTheStep)
set -euo pipefail
source_dir=$1
build_dir=$2
smoke="$source_dir/bench/smoke"
scratch=$(mktemp -d "${TMPDIR:-/tmp}/hybridctl-smoke-test.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
export TMPDIR=$scratch  # bench/smoke keeps the logs of a failed run: here, in the scratch folder
failures=0
check() { if eval "$2"; then echo "ok:     $1"; else echo "FAILED: $1"; failures=$((failures + 1)); fi; }

mkdir "$scratch/scripts"
cat >"$scratch/scripts/passing" <<'SH'
#!/bin/sh
# Records its arguments, as bench/smoke passes them.
echo "$@" >"$(dirname "$0")/../passing.args"
echo "passing: fine"
SH
cat >"$scratch/scripts/broken" <<'SH'
#!/bin/sh
echo "broken: the plan it needs is gone" >&2
exit 3
SH
printf 'not a script\n' >"$scratch/scripts/notes.txt"  # not executable: not a step
chmod +x "$scratch/scripts/passing" "$scratch/scripts/broken"

# 1. Both scripts: the step fails (1), names the broken script with its status and output.
set +e
out=$("$smoke" "$build_dir" --scripts-only --scripts-from "$scratch/scripts" 2>&1)
status=$?
set -e
echo "$out" | sed 's/^/    | /'
check "a failing script fails the step (exit 1)" '[ "$status" = 1 ]'
check "the step names the failing script and its status" 'grep -q "FAILED: $scratch/scripts/broken (exit 3)" <<<"$out"'
check "the step shows what the failing script said" 'grep -q "broken: the plan it needs is gone" <<<"$out"'
check "the summary counts one failed step of two" 'grep -q "FAILED: 1 of 2 steps" <<<"$out"'
check "the passing script ran as SCRIPT --smoke BUILD_DIR" \
  '[ "$(cat "$scratch/passing.args")" = "--smoke $(cd "$build_dir" && pwd)" ]'

# 2. Without the broken one the step passes.
rm "$scratch/scripts/broken"
set +e
out=$("$smoke" "$build_dir" --scripts-only --scripts-from "$scratch/scripts" 2>&1)
status=$?
set -e
check "passing scripts alone pass the step (exit 0)" '[ "$status" = 0 ] && grep -q "all 1 steps passed" <<<"$out"'

# 3. A build without the benchmark programs fails the step, saying how to build them.
mkdir "$scratch/build-without-benches"
set +e
out=$("$smoke" "$scratch/build-without-benches" --programs-only 2>&1)
status=$?
set -e
check "benchmark programs not built fail the step" '[ "$status" = 1 ] && grep -q "is not built: configure with -DHYBRIDCTL_BUILD_BENCH=ON" <<<"$out"'

# 4. scripts/test runs the step after the suite (and set -e makes its failure scripts/test's).
check "scripts/test runs bench/smoke" 'grep -Eq "^ *bench/smoke( |$)" "$source_dir/scripts/test" && grep -q "set -euo pipefail" "$source_dir/scripts/test"'

[ "$failures" = 0 ] || { echo "$failures check(s) failed"; exit 1; }
echo "all checks passed"
