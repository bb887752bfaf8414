#!/bin/sh
# it_frames_report.sh -- tests an animation's progress, preview and time limit.
#
# An animation's reporters with its frames rendered
# together: --progress json is one stream in which every event of a frame
# carries its number (frame 2 starts before frame 1 is done, on two
# slots), the run's own events carry none; --preview writes each frame's
# file (or, without #, the newest frame's) and ends at the frame's image;
# --time-limit stops the whole run at the limit, the frames written stay
# written, those in flight keep their finished slabs for --resume (exit
# status 124), and --resume finishes them to the bytes of single renders.
. "$(dirname "$0")/support/fakehosts.sh"
need jq cmp timeout
fh_init
cd "$FH" || exit 1
IS="$ROOT/bin/tools/imgstat"
SIZE="--size 24x16 --spp 2"
# jqe EXPR FILE: the events of FILE, as one array, make EXPR true.
jqe() { jq -se "$1" "$2" >/dev/null; }

for i in 1 2 3; do
    sed "/\"shapes\": \[/a { \"type\": \"sphere\", \"center\": [$((100 * i + 150)), 100, 300], \"radius\": 80, \"material\": \"white\" }," \
        "$ROOT/scenes/cornell.json" >"f.000$i.json"
    "$FRANJA" render "f.000$i.json" -o "ref$i.pfm" $SIZE -j 1 2>/dev/null || bad "single render of frame $i failed"
done

# --- --progress json, frames together ---
# Frame 1's last slab (rows 12:16) is held until a slab of frame 2 has
# started (10 s at most): the frames overlap only when they run together.
cat >gate.sh <<SH
#!/bin/sh
case " \$* " in *" --rows "*) ;; *) exec "$WORKER" "\$@" ;; esac
case " \$* " in
*f.0001*" --rows 12:16 "*)
    n=0
    while [ ! -e "$FH/f2started" ] && [ \$n -lt 100 ]; do sleep 0.1; n=\$((n + 1)); done
    [ -e "$FH/f2started" ] && echo overlapped >>"$FH/gatelog" || echo "no frame 2 slab in 10 s" >>"$FH/gatelog" ;;
*f.0002*) touch "$FH/f2started" ;;
esac
exec "$WORKER" "\$@"
SH
chmod +x gate.sh
printf 'here local - 2 worker=%s/gate.sh\n' "$FH" >t_gate
mkdir js
printf 'exists' >js/f.0003.pfm
timeout 120 "$FRANJA" render 'f.####.json' --frames 1-3 -o 'js/f.####.pfm' $SIZE --hosts t_gate --slab-rows 4 \
    --progress json --overwrite >ev 2>logj
check "the animation with --progress json renders" test $? -eq 0
check "frame 2 started while frame 1's last slab ran" grep -q overlapped gatelog
for i in 1 2 3; do
    check "frame $i with --progress json equals its single render" cmp -s "js/f.000$i.pfm" "ref$i.pfm"
done
check "--progress json: one JSON object a line" jqe . ev
check "--progress json: the frames event comes first" \
    test "$(head -n 1 ev | jq -c '[.event, .list, .frames]')" = '["frames","1-3",3]'
check "--progress json: frames_done comes last" \
    test "$(tail -n 1 ev | jq -c '[.event, .status, .frames, .rendered, .skipped]')" = '["frames_done","ok",3,3,0]'
# Each frame: start, progress up to every row, done, each with its number.
for i in 1 2 3; do
    check "frame $i: a start event naming its output" \
        test "$(jq -c "select(.event == \"start\" and .frame == $i) | [.output, .rows]" ev)" = "[\"js/f.000$i.pfm\",16]"
    check "frame $i: a done event, ok, every row" \
        test "$(jq -c "select(.event == \"done\" and .frame == $i) | [.status, .rows_done, .spp]" ev)" = '["ok",16,2]'
    check "frame $i: its last progress event has every row" \
        test "$(jq -s "map(select(.event == \"progress\" and .frame == $i)) | last | .rows_done" ev)" = 16
done
check "every start, progress and done event carries a frame" \
    test "$(jq -c 'select((.event == "start" or .event == "progress" or .event == "done") and (has("frame") | not))' ev | wc -l)" -eq 0
check "host ready events are the run's: no frame" \
    jqe 'any(.[]; .event == "host" and .what == "ready") and
        all(.[]; if .event == "host" and .what == "ready" then has("frame") | not else true end)' ev
# The order: frame 2 starts before frame 1 is done.
s2=$(grep -n '"event":"start","frame":2' ev | cut -d: -f1)
d1=$(grep -n '"event":"done","frame":1' ev | cut -d: -f1)
check "frame 2's start event ($s2) comes before frame 1's done event ($d1)" test -n "$s2" -a -n "$d1" -a "${s2:-0}" -lt "${d1:-0}"
grep -q '^{' logj && bad "JSON events on stderr" || ok
check "the log's last progress line counts the frames" grep -q '^franja: \[ *[0-9.]*s\] frames 3/3 rows 48/48 (100%)' logj

# A skipped frame has its event; a failing host's slab failures name the
# frame (one-row slabs: the failing host gets at least three, and is dropped).
cat >failing.sh <<SH
#!/bin/sh
case " \$* " in *" --rows "*) echo "franja-worker: simulated failure" >&2; exit 3 ;; esac
exec "$WORKER" "\$@"
SH
chmod +x failing.sh
printf 'good local - 1\nbad local - 1 worker=%s/failing.sh\n' "$FH" >t_fail
"$FRANJA" render 'f.####.json' --frames 1-3 -o 'js/f.####.pfm' $SIZE --hosts t_fail --slab-rows 4 --progress json \
    >ev2 2>log2
rm js/f.0002.pfm
"$FRANJA" render 'f.####.json' --frames 1-3 -o 'js/f.####.pfm' $SIZE --hosts t_fail --slab-rows 1 --progress json \
    >ev3 2>log3
check "the animation with a failing host renders" test $? -eq 0
check "frame 2 with a failing host equals its single render" cmp -s js/f.0002.pfm ref2.pfm
check "a skipped frame has its event" \
    test "$(jq -c 'select(.event == "skipped") | [.frame, .output]' ev3 | tr '\n' ' ')" = '[1,"js/f.0001.pfm"] [3,"js/f.0003.pfm"] '
check "every frame skipped: frames_done counts them" \
    test "$(tail -n 1 ev2 | jq -c '[.status, .rendered, .skipped]')" = '["ok",0,3]'
check "a failed slab's host event names its frame" \
    jqe 'any(.[]; .event == "host" and .what == "failed" and .frame == 2 and .host == "bad" and .y1 > .y0)' ev3
check "the drop of a host is the run's: no frame" \
    jqe 'any(.[]; .event == "host" and .what == "dropped" and (has("frame") | not))' ev3

# A single image keeps its events as they were: no frame field anywhere.
"$FRANJA" render f.0001.json -o single.pfm $SIZE -j 2 --progress json >ev4 2>/dev/null
check "a single image's events carry no frame" \
    test "$(jq -c 'select(has("frame"))' ev4 | wc -l)" -eq 0
check "a single image starts with start and ends with done" \
    test "$(head -n 1 ev4 | jq -r .event)$(tail -n 1 ev4 | jq -r .event)" = startdone

# --- --time-limit: the whole run; --preview per frame ---
# The last slab of frames 2 and 3 never ends while "hold" exists: at the
# limit frame 1 is written and frames 2 and 3 are stopped, 12 rows each.
# (A held slab is given up as stuck after some 5 s and runs again, held
# again; the host would be dropped at the third such failure, some 12 s
# in, after the limit.)
cat >hold.sh <<SH
#!/bin/sh
case " \$* " in *f.000[23]*" --rows 12:16 "*) [ -e "$FH/hold" ] && exec sleep 600 ;; esac
exec "$WORKER" "\$@"
SH
chmod +x hold.sh
printf 'here local - 2 worker=%s/hold.sh\n' "$FH" >t_hold
touch hold
t0=$(date +%s)
timeout 120 "$FRANJA" render 'f.####.json' --frames 1-3 -o 'tl/f.####.pfm' $SIZE --hosts t_hold --slab-rows 4 \
    --time-limit 10s --progress json --preview 'tl/p.####.pfm' --preview-every 1 >evt 2>logt
rc=$?
t1=$(date +%s)
check "the animation stopped by its time limit exits 124 (not $rc)" test $rc -eq 124
check "it stops at the limit ($((t1 - t0)) s)" test $((t1 - t0)) -lt 30
check "frame 1 was written within the limit" cmp -s tl/f.0001.pfm ref1.pfm
check "frames 2 and 3 were not written" test ! -e tl/f.0002.pfm -a ! -e tl/f.0003.pfm
check "frame 2 kept its 3 finished slabs" test "$(fh_slabs tl/f.0002.pfm.franja-job)" -eq 3
check "frame 3 kept its 3 finished slabs" test "$(fh_slabs tl/f.0003.pfm.franja-job)" -eq 3
check "the limit is said" grep -q "time limit of 10 s reached" logt
check "the stop names the first frame not written" \
    grep -q "the time limit stopped the animation at frame 2 (tl/f.0002.pfm): 1 of 3 frames done; rerun with --resume" logt
check "the summary says the run was stopped by the time limit" grep -q "^franja: stopped by the time limit after" logt
check "--progress json: frames 2 and 3 are done with status time_limit" \
    test "$(jq -c 'select(.event == "done") | [.frame, .status]' evt | tr '\n' ' ')" = '[1,"ok"] [2,"time_limit"] [3,"time_limit"] '
check "--progress json: frames_done says time_limit, 1 rendered" \
    test "$(tail -n 1 evt | jq -c '[.event, .status, .rendered]')" = '["frames_done","time_limit",1]'
# Each frame's preview: frame 1's is its image; frame 2's shows its 12 rows
# and the checkerboard where its held slab was (8-pixel squares of 0.02 and
# 0.08: two light, one dark across 24 pixels).
check "frame 1's preview is its image" cmp -s tl/p.0001.pfm tl/f.0001.pfm
st=$("$IS" tl/p.0002.pfm --rect 0 12 24 16)
case $st in *"mean=0.06 "*"min=0.02 max=0.08"*) ok ;; *) bad "frame 2's preview: rows 12:16 are not the checkerboard: $st" ;; esac
d=$("$IS" tl/p.0002.pfm --rect 0 0 24 12 --diff ref2.pfm)
case $d in *" max=0 "*) ok ;; *) bad "frame 2's preview: rows 0:12 are not the frame's: $d" ;; esac
rm hold
"$FRANJA" render 'f.####.json' --frames 1-3 -o 'tl/f.####.pfm' $SIZE --hosts t_hold --slab-rows 4 --time-limit 60s \
    --resume --preview 'tl/one.pfm' 2>logt2
check "the resumed animation finishes within its limit (status 0)" test $? -eq 0
check "frame 2 resumes from its 12 rows" grep -q "resuming: 12 of 16 rows already done in tl/f.0002.pfm.franja-job" logt2
for i in 1 2 3; do
    check "frame $i after the time limit and --resume equals its single render" cmp -s "tl/f.000$i.pfm" "ref$i.pfm"
done
check "a --preview without # ends at the last frame opened" cmp -s tl/one.pfm tl/f.0003.pfm
check "the first frame is skipped on resume" grep -q "frame 1 (1 of 3): tl/f.0001.pfm exists, skipped" logt2

# A bidirectional animation takes --time-limit (a single image's passes need sample sums).
"$FRANJA" render 'f.####.json' --frames 1-2 -o 'bd/f.####.pfm' $SIZE -j 2 --integrator bdpt --time-limit 60s 2>logb
check "a bidirectional animation with --time-limit renders" test $? -eq 0 -a -s bd/f.0002.pfm
summary
