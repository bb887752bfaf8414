# lib.sh -- the check counters sourced by every shell test.
#
# Sourced by the shell tests (tests/it_*.sh, and through
# tests/support/fakehosts.sh and tests/cross/lib.sh by the others): counts the
# checks and prints the closing line that tests/run.sh reads.
#
#   ok                      counts a passed check
#   bad MESSAGE...          counts a failed check and prints "FAIL: MESSAGE"
#   check DESC CMD...       runs CMD: passed if it succeeds, else "FAIL: DESC"
#   expect_error WHAT FRAGMENT CMD...
#                           CMD must fail with FRAGMENT (a fixed string) on
#                           stderr; its output is left in $T/out and $T/err
#                           ($T: the test's scratch directory).  Returns
#                           non-zero when CMD succeeded
#   need TOOL...            fails the whole test at once if a tool is missing
#   same_pixels A B         succeeds when images A and B have the same size,
#                           channels and values, whatever their headers say
#                           (final images carry their render time); oiiotool
#   summary                 prints "N passed, N failed"; returns non-zero on a
#                           failure (the test's last command)

PASSED=0
FAILED=0

ok() { PASSED=$((PASSED + 1)); }

bad() {
    FAILED=$((FAILED + 1))
    echo "FAIL: $*"
}

check() {
    desc=$1
    shift
    if "$@"; then ok; else bad "$desc"; fi
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

need() {
    for tool in "$@"; do
        if ! command -v "$tool" >/dev/null 2>&1; then
            echo "FAIL: $tool is missing (run tests/install-deps.sh)"
            echo "$PASSED passed, $((FAILED + 1)) failed"
            exit 1
        fi
    done
}

same_pixels() {
    oiiotool --fail 0 --failpercent 0 "$1" "$2" --diff 2>&1 | grep -q '^PASS'
}

summary() {
    echo "$PASSED passed, $FAILED failed"
    [ "$FAILED" -eq 0 ]
}
