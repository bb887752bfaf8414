#!/bin/sh
# make check-cross: runs tests/cross/it_*.sh in name order (the cluster test
# uses the Docker test's builds), then prints the total "N passed, N failed".
# Each test prints its own closing line; one that exits non-zero without
# counting a failure counts one.
cd "$(dirname "$0")/../.." || exit 1
total_pass=0
total_fail=0
failed=""
for t in tests/cross/it_*.sh; do
    printf '== %s\n' "$t"
    start=$(date +%s)
    out=$(sh "$t" 2>&1)
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
