#!/bin/sh
# The host table parser (franja-hosts(5)), through `franja hosts list`:
# good tables parse with defaults filled in; every bad line is refused with
# file:line and what was expected, and nothing crashes.
ROOT=$(cd "$(dirname "$0")/.." && pwd)
FRANJA="$ROOT/bin/franja"
T=$(mktemp -d /tmp/franja-hosts.XXXXXX)
trap 'rm -rf "$T"' EXIT
PASSED=0
FAILED=0

# expect_error DESC EXPECTED-TEXT TABLE-CONTENT
expect_error() {
    printf '%b' "$3" >"$T/t"
    out=$("$FRANJA" hosts list --hosts "$T/t" 2>&1)
    rc=$?
    if [ $rc -eq 2 ] && printf '%s' "$out" | grep -qF -- "$2"; then
        PASSED=$((PASSED + 1))
    else
        FAILED=$((FAILED + 1))
        echo "FAIL: $1: expected status 2 and '$2', got $rc: $out"
    fi
}

expect_ok() {
    printf '%b' "$3" >"$T/t"
    out=$("$FRANJA" hosts list --hosts "$T/t" 2>&1)
    rc=$?
    if [ $rc -eq 0 ] && printf '%s' "$out" | grep -qE -- "$2"; then
        PASSED=$((PASSED + 1))
    else
        FAILED=$((FAILED + 1))
        echo "FAIL: $1: expected status 0 and /$2/, got $rc: $out"
    fi
}

expect_ok "shipped local table" "^here +local" "$(cat "$ROOT/hosts/local.hosts")\n"
expect_ok "shipped lab table" "^alpha " "$(cat "$ROOT/hosts/lab.hosts")\n"
expect_ok "comments, blank lines, defaults" "^a +10\.0\.0\.1 +- +auto +\.cache/franja" \
    "# a comment\n\n   \t\na 10.0.0.1 - auto   # trailing comment\n"
expect_ok "port and options" "^b +h\.lab:2222 +ann +8 +/w /opt/fw arch=aarch64 os=Linux" \
    "b h.lab:2222 ann 8 workdir=/w worker=/opt/fw arch=aarch64 os=Linux identity=~/.ssh/k\n"
expect_ok "bracketed IPv6 with port" "^c +\[::1\]:22 " "c [::1]:22 - 1\n"
expect_ok "bare IPv6" "^d +fe80::1 " "d fe80::1 - 1\n"
expect_ok "CRLF line ends" "^e +x " "e x - 2\r\n"

expect_error "missing cores" "t:2: missing cores" "a 10.0.0.1 - 2\nb 10.0.0.2 root\n"
expect_error "missing user" "t:1: missing user" "a 10.0.0.1\n"
expect_error "bad port (text)" "t:1: bad port 'ssh'" "a 10.0.0.1:ssh - 2\n"
expect_error "bad port (zero)" "t:1: bad port '0'" "a 10.0.0.1:0 - 2\n"
expect_error "bad port (too big)" "t:3: bad port '65536'" "\n# x\na 10.0.0.1:65536 - 2\n"
expect_error "empty port" "t:1: bad port ''" "a 10.0.0.1: - 2\n"
expect_error "duplicate name" "t:3: duplicate host name 'a' (first defined on line 1)" \
    "a 10.0.0.1 - 2\nb 10.0.0.2 - 2\na 10.0.0.3 - 2\n"
expect_error "bad cores" "t:1: cores 'many': expected 1..4096 or 'auto'" "a h - many\n"
expect_error "zero cores" "t:1: cores '0'" "a h - 0\n"
expect_error "negative cores" "t:1: cores '-2'" "a h - -2\n"
expect_error "unknown key" "t:1: unknown key 'color'" "a h - 2 color=red\n"
expect_error "not key=value" "t:1: 'fast': expected key=value" "a h - 2 fast\n"
expect_error "empty value" "t:1: empty workdir" "a h - 2 workdir=\n"
expect_error "key twice" "t:1: worker= given twice" "a h - 2 worker=/a worker=/b\n"
expect_error "bad name" "t:1: host name 'a/b'" "a/b h - 2\n"
expect_error "local with port" "t:1: address 'local' takes no port" "a local:22 - 2\n"
expect_error "unclosed bracket" "t:1: address '[::1': '[' without ']'" "a [::1 - 2\n"
expect_error "empty table" "t: no hosts" "# nothing\n\n"
expect_error "binary junk" "t: binary data" "a h - 2\n\000\001\n"
expect_error "overlong line" "t:1: line longer than" "$(head -c 5000 /dev/zero | tr '\0' a)\n"
expect_error "overlong field" "t:1: worker is longer than" "a h - 2 worker=/$(head -c 600 /dev/zero | tr '\0' a)\n"

out=$("$FRANJA" hosts list --hosts "$T/missing" 2>&1)
if [ $? -eq 2 ] && printf '%s' "$out" | grep -q "missing: cannot open host table"; then
    PASSED=$((PASSED + 1))
else
    FAILED=$((FAILED + 1))
    echo "FAIL: missing file: $out"
fi
# The render command reports the same errors before doing anything.
printf 'a h - 2\na h - 2\n' >"$T/dup"
out=$("$FRANJA" render "$ROOT/scenes/cornell.json" -o "$T/x.png" --hosts "$T/dup" 2>&1)
if [ $? -eq 2 ] && printf '%s' "$out" | grep -q "dup:2: duplicate host name"; then
    PASSED=$((PASSED + 1))
else
    FAILED=$((FAILED + 1))
    echo "FAIL: render with a bad table: $out"
fi

echo "$PASSED passed, $FAILED failed"
[ "$FAILED" -eq 0 ]
