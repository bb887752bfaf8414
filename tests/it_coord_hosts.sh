#!/bin/sh
# it_coord_hosts.sh -- tests the host table parser through franja hosts list.
#
# The host table parser (franja-hosts(5)), through `franja hosts list`:
# good tables parse with defaults filled in; every bad line is refused with
# file:line and what was expected, and nothing crashes.
ROOT=$(cd "$(dirname "$0")/.." && pwd)
. "$ROOT/tests/support/lib.sh"
FRANJA="$ROOT/bin/franja"
T=$(mktemp -d /tmp/franja-hosts.XXXXXX)
trap 'rm -rf "$T"' EXIT

# expect_status DESC STATUS GREP-MODE PATTERN CMD...: CMD exits with STATUS
# and prints (on stdout or stderr) PATTERN, matched with grep -F or -E.
expect_status() {
    desc=$1 status=$2 mode=$3 pattern=$4
    shift 4
    out=$("$@" 2>&1)
    rc=$?
    if [ $rc -eq "$status" ] && printf '%s' "$out" | grep -q "$mode" -- "$pattern"; then
        ok
    else
        bad "$desc: expected status $status and '$pattern', got $rc: $out"
    fi
}

# table_ok DESC REGEX TABLE-CONTENT / table_error DESC TEXT TABLE-CONTENT:
# `franja hosts list` of a table with that content (printf %b escapes).
list_table() {
    printf '%b' "$1" >"$T/t"
    "$FRANJA" hosts list --hosts "$T/t"
}
table_ok() { expect_status "$1" 0 -E "$2" list_table "$3"; }
table_error() { expect_status "$1" 2 -F "$2" list_table "$3"; }

table_ok "shipped local table" "^here +local" "$(cat "$ROOT/hosts/local.hosts")\n"
table_ok "shipped lab table" "^alpha " "$(cat "$ROOT/hosts/lab.hosts")\n"
table_ok "comments, blank lines, defaults" "^a +10\.0\.0\.1 +- +auto +\.cache/franja" \
    "# a comment\n\n   \t\na 10.0.0.1 - auto   # trailing comment\n"
table_ok "port and options" "^b +h\.lab:2222 +ann +8 +/w /opt/fw arch=aarch64 os=Linux" \
    "b h.lab:2222 ann 8 workdir=/w worker=/opt/fw arch=aarch64 os=Linux identity=~/.ssh/k\n"
table_ok "bracketed IPv6 with port" "^c +\[::1\]:22 " "c [::1]:22 - 1\n"
table_ok "bare IPv6" "^d +fe80::1 " "d fe80::1 - 1\n"
table_ok "CRLF line ends" "^e +x " "e x - 2\r\n"

table_error "missing cores" "t:2: missing cores" "a 10.0.0.1 - 2\nb 10.0.0.2 root\n"
table_error "missing user" "t:1: missing user" "a 10.0.0.1\n"
table_error "bad port (text)" "t:1: bad port 'ssh'" "a 10.0.0.1:ssh - 2\n"
table_error "bad port (zero)" "t:1: bad port '0'" "a 10.0.0.1:0 - 2\n"
table_error "bad port (too big)" "t:3: bad port '65536'" "\n# x\na 10.0.0.1:65536 - 2\n"
table_error "empty port" "t:1: bad port ''" "a 10.0.0.1: - 2\n"
table_error "duplicate name" "t:3: duplicate host name 'a' (first defined on line 1)" \
    "a 10.0.0.1 - 2\nb 10.0.0.2 - 2\na 10.0.0.3 - 2\n"
table_error "bad cores" "t:1: cores 'many': expected 1..4096 or 'auto'" "a h - many\n"
table_error "zero cores" "t:1: cores '0'" "a h - 0\n"
table_error "negative cores" "t:1: cores '-2'" "a h - -2\n"
table_error "unknown key" "t:1: unknown key 'color'" "a h - 2 color=red\n"
table_error "not key=value" "t:1: 'fast': expected key=value" "a h - 2 fast\n"
table_error "empty value" "t:1: empty workdir" "a h - 2 workdir=\n"
table_error "key twice" "t:1: worker= given twice" "a h - 2 worker=/a worker=/b\n"
table_error "bad name" "t:1: host name 'a/b'" "a/b h - 2\n"
table_error "local with port" "t:1: address 'local' takes no port" "a local:22 - 2\n"
table_error "unclosed bracket" "t:1: address '[::1': '[' without ']'" "a [::1 - 2\n"
table_error "empty table" "t: no hosts" "# nothing\n\n"
table_error "binary junk" "t: binary data" "a h - 2\n\000\001\n"
table_error "overlong line" "t:1: line longer than" "$(head -c 5000 /dev/zero | tr '\0' a)\n"
table_error "overlong field" "t:1: worker is longer than" "a h - 2 worker=/$(head -c 600 /dev/zero | tr '\0' a)\n"
table_error "the first repeated name" "t:4: duplicate host name 'b' (first defined on line 2)" \
    "a h - 1\nb h - 1\nc h - 1\nb h - 1\na h - 1\nc h - 1\n"
table_error "a repeated name before a bad line" "t:3: duplicate host name 'a'" "a h - 1\n\na h - 1\nb h\n"
table_error "a bad line before a repeated name" "t:2: missing user" "a h - 1\nb h\na h - 1\n"

# A table of at most 65536 hosts is read at once (repeated names are
# found by sorting them, not by comparing every pair); one more host is
# refused, so that no table takes unbounded memory or minutes to read.
awk 'BEGIN { for (i = 65535; i >= 0; i--) printf "h%07d local - 1\n", i }' >"$T/many"
expect_status "65536 hosts" 0 -E "^h0065535 +local" "$FRANJA" hosts list --hosts "$T/many"
{ sed '$d' "$T/many"; echo "h0000007 local - 2"; } >"$T/dup-last"
expect_status "a repeated name on line 65536" 2 -F \
    "dup-last:65536: duplicate host name 'h0000007' (first defined on line 65529)" \
    "$FRANJA" hosts list --hosts "$T/dup-last"
echo "x local - 1" >>"$T/many"
expect_status "65537 hosts" 2 -F "many:65537: more than 65536 hosts" "$FRANJA" hosts list --hosts "$T/many"

expect_status "missing file" 2 -F "missing: cannot open host table" "$FRANJA" hosts list --hosts "$T/missing"
# The render command reports the same errors before doing anything.
printf 'a h - 2\na h - 2\n' >"$T/dup"
expect_status "render with a bad table" 2 -F "dup:2: duplicate host name" \
    "$FRANJA" render "$ROOT/scenes/cornell.json" -o "$T/x.png" --hosts "$T/dup"

summary
