#!/bin/sh
# it_monitor_guard.sh -- tests the monitor's token and request deadlines.
#
# Who may use franja render --monitor, and for how
# long: without --monitor-open every request needs the token of the address
# printed on stderr (none, or a wrong one, gets 403); with it, none is
# needed.  Clients that trickle a header line a second hold no connection
# longer than the 5 s a request header is given, and neither 32 of them nor
# 100 keep a prompt request out: it is answered within 2 s.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need curl jq python3
T=$(mktemp -d)
pid=""
slow=""
trap '[ -n "$pid" ] && kill $pid 2>/dev/null; [ -n "$slow" ] && kill $slow 2>/dev/null; [ -z "${KEEP:-}" ] && rm -rf "$T"' EXIT
ROOT=$(pwd)
F="$ROOT/bin/franja"
W="$ROOT/bin/franja-worker"

# A host whose slabs never end (and take no CPU): the render, and its
# monitor, last until they are interrupted.
cat >"$T/hold.sh" <<SH
#!/bin/sh
case " \$* " in *" --rows "*) exec sleep 600 ;; esac
exec "$W" "\$@"
SH
chmod +x "$T/hold.sh"
printf 'here local - 1 worker=%s\n' "$T/hold.sh" >"$T/hosts"

# start NAME ARGS...: a render to $T/NAME.png with a monitor in the
# background ($pid); its address, as printed on $T/NAME.log, in $url.
start() {
    log=$T/$1.log
    out=$T/$1.png
    shift
    : >"$log"
    "$F" render scenes/spheres.json -o "$out" --size 8x8 --spp 1 --hosts "$T/hosts" --monitor 0 "$@" \
        >/dev/null 2>"$log" &
    pid=$!
    url=""
    i=0
    while [ -z "$url" ] && [ $i -lt 300 ] && kill -0 $pid 2>/dev/null; do
        url=$(sed -n 's|^franja: monitor on \(http://127\.0\.0\.1:[0-9]*/.*\)$|\1|p' "$log")
        sleep 0.1
        i=$((i + 1))
    done
}

stop() {
    kill -INT $pid
    wait $pid
    pid=""
}

# code URL: the HTTP status of a GET of URL, 000 when there was no answer within 2 s.
code() { curl -s -o /dev/null -m 2 -w '%{http_code}' "$1"; }

# Another render's token is another.
start a
other=$(printf '%s\n' "$url" | sed -n 's|.*?token=||p')
stop
start b
token=$(printf '%s\n' "$url" | sed -n 's|^http://127\.0\.0\.1:[0-9]*/?token=\([0-9a-f]*\)$|\1|p')
[ ${#token} = 32 ] && ok || { bad "no address with a 32-digit token on stderr: $(cat "$T/b.log")"; summary; exit 1; }
[ -n "$other" ] && [ "$other" != "$token" ] && ok || bad "two monitors with the same token: $token, $other"
base=${url%%/?token=*}

# Without the token, with a wrong one, one too short or too long: 403, for every path.
wrong=$(printf '%s' "$token" | tr '0-9a-f' '1-9a-f0')
for u in "$base/" "$base/state.json" "$base/image.png" "$base/nothing" "$base/state.json?token=" \
    "$base/state.json?token=$wrong" "$base/state.json?token=${token%?}" "$base/state.json?token=${token}0" \
    "$base/state.json?other=$token"; do
    c=$(code "$u")
    [ "$c" = 403 ] && ok || bad "$u without the token got HTTP $c"
done
curl -s -m 2 "$base/state.json" | grep -q 'needs its token' && ok || bad "the refusal does not say what is missing"
# With it: the page, the state, and a page whose script carries the token on.
[ "$(code "$base/?token=$token")" = 200 ] && ok || bad "the page with the token: HTTP $(code "$base/?token=$token")"
curl -sf -m 2 "$base/state.json?token=$token" | jq -e '.status == "rendering" and .width == 8' >/dev/null && ok ||
    bad "state.json with the token: $(curl -s -m 2 "$base/state.json?token=$token")"
curl -s -m 2 "$base/?token=$token" | grep -q "fetch('state.json' + query" && ok || bad "the page's script does not carry the token"

# One client trickling a header line a second is cut at its deadline
# (5 s), not kept as long as it keeps trickling.
python3 tests/support/slow_clients.py "${base##*:}" 1 7 >"$T/one"
longest=$(sed -n 's/.* longest \([0-9.]*\)$/\1/p' "$T/one")
awk -v l="$longest" 'BEGIN { exit !(l != "" && l >= 4 && l < 6.5) }' && ok ||
    bad "a trickling client was not cut after 5 s: $(cat "$T/one")"

# slow_then N: N trickling clients for 10 s; while they are connected, a
# prompt request is answered within 2 s, at once and again after the
# first of them were cut and came back.
slow_then() {
    : >"$T/slow"
    python3 tests/support/slow_clients.py "${base##*:}" "$1" 10 >"$T/slow" &
    slow=$!
    i=0
    until grep -q connected "$T/slow" || [ $i -ge 50 ]; do
        sleep 0.1
        i=$((i + 1))
    done
    grep -q connected "$T/slow" && ok || bad "$1 slow clients could not connect"
    for pause in 0 3 3; do
        sleep $pause
        t0=$(date +%s.%N)
        c=$(code "$base/state.json?token=$token")
        t1=$(date +%s.%N)
        [ "$c" = 200 ] && ok || bad "with $1 slow clients connected, state.json got HTTP $c within 2 s"
        awk -v a="$t0" -v b="$t1" 'BEGIN { exit !(b - a < 2) }' && ok || bad "with $1 slow clients: $t0 .. $t1"
    done
    wait $slow
    slow=""
    grep -q '^opened [0-9]* closed_by_server [1-9]' "$T/slow" && ok ||
        bad "$1 slow clients: none was cut: $(cat "$T/slow")"
}
slow_then 32
slow_then 100
kill -0 $pid 2>/dev/null && ok || bad "the render ended under the slow clients: $(cat "$T/b.log")"
stop

# --monitor-open: no token, none needed.
start c --monitor-open
case "$url" in
http://127.0.0.1:*/) ok ;;
*) bad "--monitor-open: the address is not a plain one: $(cat "$T/c.log")" ;;
esac
[ "$(code "${url}state.json")" = 200 ] && ok || bad "--monitor-open: state.json got HTTP $(code "${url}state.json")"
stop

expect_error "--monitor-open alone" "--monitor-open needs --monitor PORT" "$F" render scenes/spheres.json \
    --monitor-open
summary
