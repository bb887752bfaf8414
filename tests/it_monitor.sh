#!/bin/sh
# it_monitor.sh -- tests the --monitor web page in a real browser.
#
# franja render --monitor PORT: a live page on 127.0.0.1,
# at the address with its token that franja prints (it_monitor_guard.sh
# checks the token and the limits), loaded in a real browser (headless chromium) during a render on two
# hosts, one of which fails every slab; the page shows the image so far,
# each host's state, slots, rows and failures, the ETA and the events, and
# --progress json carries the same host events; for an animation rendered
# with its frames together, the page shows which frames are written and
# which are rendering, with their rows, and the newest frame's image.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need chromium curl jq ss
T=$(mktemp -d)
pid=""
trap '[ -n "$pid" ] && kill $pid 2>/dev/null; [ -z "${KEEP:-}" ] && rm -rf "$T"' EXIT
ROOT=$(pwd)
F="$ROOT/bin/franja"
W="$ROOT/bin/franja-worker"

# Host "bad" answers the probe like a worker and fails every slab.
cat >"$T/bad.sh" <<SH
#!/bin/sh
case " \$* " in *" --rows "*) ;; *) exec "$W" "\$@" ;; esac
echo "franja-worker: simulated failure" >&2
exit 3
SH
chmod +x "$T/bad.sh"
printf 'good local - 1\nbad local - 1 worker=%s\n' "$T/bad.sh" >"$T/hosts"

# The browser as this test's own: a private profile, no sandbox (it may run as root).
browse() {
    timeout 120 chromium --headless --no-sandbox --disable-gpu --user-data-dir="$T/chrome" \
        --virtual-time-budget=4000 "$@" 2>>"$T/chrome.log"
}

# A render far longer than the checks (one row takes seconds here; it is
# interrupted once they are done), one-row slabs so that rows come early.
"$F" render scenes/cornell.json -o "$T/out.png" --size 24x24 --spp 16384 --slab-rows 1 --hosts "$T/hosts" \
    --monitor 0 --progress json >"$T/events" 2>"$T/log" &
pid=$!
port=""
i=0
while [ -z "$port" ] && [ $i -lt 300 ] && kill -0 $pid 2>/dev/null; do
    port=$(sed -n 's|^franja: monitor on http://127.0.0.1:\([0-9]*\)/?token=[0-9a-f]*$|\1|p' "$T/log")
    sleep 0.1
    i=$((i + 1))
done
[ -n "$port" ] && ok || { bad "no monitor address on stderr: $(cat "$T/log")"; summary; exit 1; }
URL="http://127.0.0.1:$port"
Q="?token=$(sed -n 's|^franja: monitor on http://127.0.0.1:[0-9]*/?token=||p' "$T/log")"

# Wait (a minute at most) until two rows are done and host bad is dropped.
state() { curl -sf "$URL/state.json$Q"; }
i=0
until state | jq -e '.rows_done >= 2 and (.hosts[] | select(.name == "bad") | .state | startswith("dropped"))' \
    >/dev/null 2>&1 || [ $i -ge 600 ]; do
    sleep 0.1
    i=$((i + 1))
done
s=$(state)
echo "$s" | jq -e '.status == "rendering" and .width == 24 and .height == 24 and .spp == 16384 and .rows == 24' \
    >/dev/null && ok || bad "state.json: $s"
before=$(echo "$s" | jq .rows_done)
[ "$before" -ge 2 ] && ok || bad "no rows done after a minute: $s"

# Only this machine: bound to 127.0.0.1, and a request naming another host is refused.
ss -ltnH "sport = :$port" | grep -q " 127\.0\.0\.1:$port " && ok ||
    bad "the monitor does not listen on 127.0.0.1 only: $(ss -ltnH "sport = :$port")"
code=$(curl -s -o /dev/null -w '%{http_code}' -H 'Host: example.com' "$URL/state.json$Q")
[ "$code" = 403 ] && ok || bad "a request for Host example.com got HTTP $code"
code=$(curl -s -o /dev/null -w '%{http_code}' -X POST "$URL/state.json$Q")
[ "$code" = 405 ] && ok || bad "a POST got HTTP $code"
curl -sf "$URL/image.png$Q" -o "$T/now.png" && [ "$(head -c 8 "$T/now.png" | od -An -c | tr -d ' ')" = '211PNG\r\n032\n' ] &&
    ok || bad "image.png is not a PNG"

# The page in a browser, after its script ran: what it shows. Host good is
# idle for a moment between two slabs; a page caught then is loaded again.
i=0
while :; do
    browse --dump-dom "$URL/$Q" >"$T/dom.html"
    grep -q '<tr><td>good</td><td class="state">idle</td><td>0/1</td>' "$T/dom.html" && [ $i -lt 5 ] || break
    i=$((i + 1))
done
grep -q 'id="status" class="rendering">rendering<' "$T/dom.html" && ok || bad "the page does not say rendering"
grep -q 'id="imgrows">image: 24x24, [0-9]* rows rendered<' "$T/dom.html" && ok ||
    bad "the page's image is not loaded: $(grep -o 'id="imgrows">[^<]*' "$T/dom.html")"
grep -Eq '<img id="img"[^>]*src="blob:' "$T/dom.html" && ok || bad "no image on the page"
rows=$(sed -n 's|.*id="rows">\([0-9]*\)/24<.*|\1|p' "$T/dom.html")
[ -n "$rows" ] && [ "$rows" -ge "$before" ] && ok || bad "the page shows rows '$rows', fewer than $before"
grep -Eq 'id="eta">[0-9hms]+<' "$T/dom.html" && ok || bad "no ETA on the page: $(grep -o 'id="eta">[^<]*' "$T/dom.html")"
grep -q '<tr><td>good</td><td class="state">rendering</td><td>1/1</td>' "$T/dom.html" && ok ||
    bad "host good is not shown rendering with 1/1 slots: $(grep -o '<tr><td>good</td>.*</tr>' "$T/dom.html")"
grep -Eq '<tr><td>bad</td><td class="state down">dropped: [^<]*</td><td>0/1</td><td>0</td><td>0.00</td><td class="fail">3</td>' \
    "$T/dom.html" && ok || bad "host bad is not shown dropped with 3 failures: $(grep -o '<tr><td>bad</td>.*</tr>' "$T/dom.html")"
grep -q '<li class="failed">[^<]*bad: rows [0-9]*:[0-9]* failed on bad' "$T/dom.html" && ok || bad "no failure event on the page"
grep -q '<li class="dropped">[^<]*dropping host bad' "$T/dom.html" && ok || bad "no drop event on the page"
# A screenshot of it is a PNG of the window's size.
browse --window-size=800,480 --screenshot="$T/shot.png" "$URL/$Q" >/dev/null
[ -s "$T/shot.png" ] && [ "$(head -c 4 "$T/shot.png" | od -An -c | tr -d ' ')" = '211PNG' ] && ok ||
    bad "no screenshot: $(tail -n 3 "$T/chrome.log")"

# The port is taken now: another monitor on it says so before rendering.
expect_error "port in use" "cannot listen on 127.0.0.1:$port" "$F" render scenes/spheres.json -o "$T/x.png" \
    --size 8x8 --spp 1 --monitor "$port"

# Interrupted: exits 130; the JSON stream has the host events.
kill -INT $pid
wait $pid
rc=$?
pid=""
[ $rc = 130 ] && ok || bad "the interrupted render exited $rc: $(tail -n 3 "$T/log")"
jq -e . "$T/events" >/dev/null && ok || bad "--progress json: not JSON: $(head -n 3 "$T/events")"
[ "$(jq -c 'select(.event == "host" and .what == "failed" and .host == "bad" and .y1 > .y0)' "$T/events" | wc -l)" = 3 ] &&
    ok || bad "--progress json: not three failures of host bad: $(cat "$T/events")"
jq -se 'any(.[]; .event == "host" and .what == "dropped" and .host == "bad")' "$T/events" >/dev/null && ok ||
    bad "--progress json: no drop event"
jq -se 'any(.[]; .event == "host" and .what == "ready" and .host == "good")' "$T/events" >/dev/null && ok ||
    bad "--progress json: no ready event"
jq -se 'any(.[]; .event == "done" and .status == "interrupted")' "$T/events" >/dev/null && ok ||
    bad "--progress json: no interrupted done event"
curl -sf "$URL/state.json$Q" >/dev/null && bad "the monitor still answers after the render" || ok

# An animation: frames 1-3 of a sphere moving; the last slab of frames 2
# and 3 never ends while "hold" exists, so the page is caught with frame 1
# written and frames 2 and 3 rendering, 12 of 16 rows each.  The other
# slabs take 2 s each, so that the held ones are given up as stuck (8
# times a slab's time, plus 5 s) only long after the checks.
for i in 1 2 3; do
    sed "/\"shapes\": \[/a { \"type\": \"sphere\", \"center\": [$((100 * i + 150)), 100, 300], \"radius\": 80, \"material\": \"white\" }," \
        scenes/cornell.json >"$T/f.000$i.json"
done
cat >"$T/hold.sh" <<SH
#!/bin/sh
case " \$* " in
*f.000[23]*" --rows 12:16 "*) [ -e "$T/hold" ] && exec sleep 600 ;;
*" --rows "*) sleep 2 ;;
esac
exec "$W" "\$@"
SH
chmod +x "$T/hold.sh"
printf 'here local - 2 worker=%s\n' "$T/hold.sh" >"$T/thold"
touch "$T/hold"
"$F" render "$T/f.####.json" --frames 1-3 -o "$T/anim/f.####.pfm" --size 24x16 --spp 2 --slab-rows 4 \
    --hosts "$T/thold" --monitor 0 --progress json >"$T/aevents" 2>"$T/alog" &
pid=$!
port=""
i=0
while [ -z "$port" ] && [ $i -lt 300 ] && kill -0 $pid 2>/dev/null; do
    port=$(sed -n 's|^franja: monitor on http://127.0.0.1:\([0-9]*\)/?token=[0-9a-f]*$|\1|p' "$T/alog")
    sleep 0.1
    i=$((i + 1))
done
[ -n "$port" ] && ok || bad "an animation: no monitor address on stderr: $(cat "$T/alog")"
URL="http://127.0.0.1:$port"
Q="?token=$(sed -n 's|^franja: monitor on http://127.0.0.1:[0-9]*/?token=||p' "$T/alog")"
i=0
until state | jq -e '.frames.states == "drr" and ([.frames.current[].rows_done] == [12, 12])' >/dev/null 2>&1 ||
    [ $i -ge 600 ]; do
    sleep 0.1
    i=$((i + 1))
done
s=$(state)
echo "$s" | jq -e '.status == "rendering" and .frames.list == "1-3" and .frames.count == 3 and .frames.done == 1 and
    .frames.rendering == 2 and .frames.waiting == 0 and .frames.shown == 3 and
    ([.frames.current[] | [.frame, .rows_done, .rows]] == [[2, 12, 16], [3, 12, 16]]) and
    .width == 24 and .height == 16 and (.eta_s | type) == "number"' >/dev/null && ok ||
    bad "an animation's state.json: $s"
curl -sf "$URL/image.png$Q" -o "$T/anim.png" && [ "$(head -c 8 "$T/anim.png" | od -An -c | tr -d ' ')" = '211PNG\r\n032\n' ] &&
    ok || bad "an animation's image.png is not a PNG"
browse --dump-dom "$URL/$Q" >"$T/adom.html"
grep -q 'id="fsum">1 written, 2 rendering, 0 skipped, 0 waiting of 3<' "$T/adom.html" && ok ||
    bad "the page does not count the frames: $(grep -o 'id="fsum">[^<]*' "$T/adom.html")"
grep -q '<div id="strip"><span class="d" title="frame 1: written"></span><span class="r" title="frame 2: rendering"></span><span class="r" title="frame 3: rendering"></span></div>' \
    "$T/adom.html" && ok || bad "the page's strip of frames: $(grep -o '<div id="strip">.*</div>' "$T/adom.html" | head -c 400)"
grep -q "<tr><td>2</td><td class=\"state\">$T/anim/f.0002.pfm</td><td>12/16</td><td>75</td></tr>" "$T/adom.html" && ok ||
    bad "the page does not show frame 2 rendering: $(grep -o '<table id="current">.*</table>' "$T/adom.html" | head -c 600)"
grep -q 'id="imgrows">image: frame 3, 24x16, 12 rows rendered<' "$T/adom.html" && ok ||
    bad "the page does not show frame 3's image: $(grep -o 'id="imgrows">[^<]*' "$T/adom.html")"
kill -INT $pid
wait $pid
rc=$?
pid=""
rm "$T/hold"
[ $rc = 130 ] && ok || bad "the interrupted animation exited $rc: $(tail -n 3 "$T/alog")"
[ "$(jq -c 'select(.event == "done") | [.frame, .status]' "$T/aevents" | tr '\n' ' ')" = \
    '[1,"ok"] [2,"interrupted"] [3,"interrupted"] ' ] && ok || bad "an animation's done events: $(cat "$T/aevents")"
curl -sf "$URL/state.json$Q" >/dev/null && bad "the animation's monitor still answers after the render" || ok

# Bad values and a port in use.
expect_error "--monitor x" "--monitor: 'x' is not an integer in 0..65535" "$F" render scenes/spheres.json --monitor x
expect_error "--monitor 70000" "0..65535" "$F" render scenes/spheres.json --monitor 70000
# A short render with a monitor ends by itself and writes its image.
"$F" render scenes/spheres.json -o "$T/s.png" --size 16x16 --spp 2 -j 1 --monitor 0 >/dev/null 2>"$T/log2" &&
    [ -s "$T/s.png" ] && ok || bad "a short render with --monitor failed: $(cat "$T/log2")"
summary
