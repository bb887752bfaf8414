#!/bin/sh
# run.sh -- runs the tests and prints the total passed and failed.
#
# Run the given tests (default: every test program bin/tests/test_* and
# integration script tests/it_*.sh in name order, then a short fuzz pass:
# tests/fuzz/run.sh, FUZZ_TEST_SECONDS (default 10) per libFuzzer target
# from its seeds, failing on any finding), then print the total as
# "N passed, N failed".  Each test prints its own "N passed, N failed"
# line; a test that exits non-zero counts at least one failure even if it
# printed nothing.  `make check-cross` runs tests/cross/it_*.sh through it.
cd "$(dirname "$0")/.." || exit 1
# A cap on samples per pixel left in the caller's environment would change
# what the tests measure; tests/it_docs.sh sets its own.
unset FRANJA_MAX_SPP
[ $# -gt 0 ] || set -- bin/tests/test_* tests/it_*.sh tests/fuzz/run.sh
total_pass=0
total_fail=0
failed=""
for t in "$@"; do
    [ -e "$t" ] || continue
    case "$t" in
    tests/fuzz/run.sh) cmd="sh $t ${FUZZ_TEST_SECONDS:-10}" ;;
    *.sh) cmd="sh $t" ;;
    *) cmd="$t" ;;
    esac
    printf '== %s\n' "$t"
    start=$(date +%s)
    out=$($cmd 2>&1)
    rc=$?
    printf '%s\n' "$out" | tail -n 60
    line=$(printf '%s\n' "$out" | grep -E '^[0-9]+ passed, [0-9]+ failed' | tail -n 1)
    p=$(printf '%s' "$line" | sed -E 's/^([0-9]+) passed.*/\1/')
    f=$(printf '%s' "$line" | sed -E 's/^[0-9]+ passed, ([0-9]+) failed.*/\1/')
    [ -n "$p" ] || p=0
    [ -n "$f" ] || f=0
    if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi
    total_pass=$((total_pass + p))
    total_fail=$((total_fail + f))
    [ "$f" -eq 0 ] || failed="$failed $t"
    printf '   (%ss)\n' $(($(date +%s) - start))
done
[ -z "$failed" ] || printf 'failing:%s\n' "$failed"
echo "$total_pass passed, $total_fail failed"
[ "$total_fail" -eq 0 ]
