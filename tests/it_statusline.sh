#!/bin/sh
# it_statusline.sh -- tests the live progress line fits the terminal.
#
# The live progress line on a terminal (a pseudo-terminal
# made by script(1)) fits the terminal's width, from TIOCGWINSZ or, when the
# terminal has no size, from $COLUMNS, and shows the elapsed time and the ETA.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need script stty
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
F="$(pwd)/bin/franja"
# Each slab's worker waits 0.1 s first, so the render lasts a few seconds
# however fast the machine is and the line (drawn every 0.25 s) is drawn
# while rows remain, where it shows an ETA.
cat >"$T/slow.sh" <<SH
#!/bin/sh
case " \$* " in *" --rows "*) sleep 0.1 ;; esac
exec "$(pwd)/bin/franja-worker" "\$@"
SH
chmod +x "$T/slow.sh"
printf 'local local - 2 worker=%s\n' "$T/slow.sh" >"$T/hosts"
R="$F render scenes/cornell.json -o $T/out.pfm --size 48x48 --spp 16 --hosts $T/hosts --slab-rows 1"

# widest LOG: the longest progress line drawn (the pieces between carriage
# returns, without the erase sequence), and how many there were.
widest() {
    tr '\r' '\n' <"$1" | sed 's/\x1b\[K//g' | grep '^rows [0-9]' | awk '
        length($0) > w { w = length($0) } { n++ } END { print w + 0, n + 0 }'
}

script -qec "stty cols 60; $R" /dev/null >"$T/tty60" 2>&1
set -- $(widest "$T/tty60")
[ "$2" -ge 1 ] && ok || bad "no live line on a terminal: $(head -c 300 "$T/tty60")"
[ "$1" -le 59 ] && ok || bad "a live line of $1 characters on a 60-column terminal"
grep -q 'elapsed [0-9]' "$T/tty60" && ok || bad "no elapsed time on the live line"
grep -q 'ETA [0-9]' "$T/tty60" && ok || bad "no ETA on the live line"

script -qec "stty cols 200; $R" /dev/null >"$T/tty200" 2>&1
set -- $(widest "$T/tty200")
[ "$1" -gt 59 ] && [ "$1" -le 199 ] && ok || bad "on a 200-column terminal the widest line has $1 characters"
grep -q 'local:[0-9]*/2 ' "$T/tty200" && ok || bad "a wide terminal does not show the host"

# No size on the terminal: $COLUMNS.
script -qec "stty cols 0 rows 0; COLUMNS=45 $R" /dev/null >"$T/cols45" 2>&1
set -- $(widest "$T/cols45")
[ "$2" -ge 1 ] && [ "$1" -le 44 ] && ok || bad "with COLUMNS=45 the widest line has $1 characters ($2 lines)"

# Not a terminal: plain lines with the same figures, at the end at least.
$R 2>"$T/log"
grep -q '^franja: \[ *[0-9.]*s\] rows 48/48 (100%)  elapsed ' "$T/log" && ok ||
    bad "no plain progress line in a log: $(cat "$T/log")"
summary
