# lib.sh -- sourced by the shell tests (tests/it_*.sh): counts the checks
# and prints the closing line that tests/run.sh reads.
#
#   ok                      counts a passed check
#   bad MESSAGE...          counts a failed check and prints "FAIL: MESSAGE"
#   expect_error WHAT FRAGMENT CMD...
#                           CMD must fail with FRAGMENT (a fixed string) on
#                           stderr; its output is left in $T/out and $T/err
#                           ($T: the test's scratch directory).  Returns
#                           non-zero when CMD succeeded
#   summary                 prints "N passed, N failed"; returns non-zero on a
#                           failure (the test's last command)

PASSED=0
FAILED=0

ok() { PASSED=$((PASSED + 1)); }

bad() {
    FAILED=$((FAILED + 1))
    echo "FAIL: $*"
}

expect_error() {
    what=$1 frag=$2
    shift 2
    if "$@" >"$T/out" 2>"$T/err"; then
        bad "$what: exit status 0"
        return 1
    fi
    grep -qF -- "$frag" "$T/err" && ok || bad "$what: stderr lacks '$frag': $(cat "$T/err")"
}

summary() {
    echo "$PASSED passed, $FAILED failed"
    [ "$FAILED" -eq 0 ]
}
