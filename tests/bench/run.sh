#!/bin/sh
# run.sh -- runs every benchmark script of tests/bench in turn.
#
# Runs every benchmark script tests/bench/*.sh (except this one) in turn.
# Each prints its own figures: ratios against a reference measured in the
# same run, medians, and the machine.
cd "$(dirname "$0")/../.." || exit 1
rc=0
for b in tests/bench/*.sh; do
    [ "$b" = tests/bench/run.sh ] && continue
    printf '== %s\n' "$b"
    sh "$b" || rc=1
done
exit $rc
