#!/bin/sh
# it_docs_fail.sh -- tests it_docs.sh fails on broken documentation.
#
# tests/it_docs.sh fails on documentation that does not
# do what it says, naming the file and line: a document of broken examples
# (written here, never into the repository) must give exactly the failures
# listed below, and its one good example must pass.
#
#   - an example without an annotation (Markdown and man page);
#   - an annotation that says nothing the example shows;
#   - a shell example that fails, one whose stdout lacks the text its
#     annotation quotes, an error example that succeeds, one that fails
#     with another message, one that does not create its file;
#   - a one-sided lamp facing away from the room (the shapes fragment's
#     lamp pointing at the ceiling, "lights the dark room" false);
#   - a scene fragment whose values are not those of the scene it claims
#     to come from;
#   - an option that franja does not have, in an example that is skipped;
#   - an unknown check, an annotation before text instead of an example.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

cat >"$T/bad.md" <<'MD'
# Broken examples

```sh
echo unannotated
```

<!-- expect: exit 0 -->
```sh
echo nothing-claimed
```

<!-- expect: stdout hello -->
```sh
false
```

<!-- expect: stdout "hello there" -->
```sh
echo goodbye
```

<!-- expect: error "no such scene" -->
```sh
true
```

<!-- expect: error "no such scene" -->
```sh
bin/franja render scenes/cornell.json --samples 4
```

<!-- expect: file made.txt -->
```sh
echo not-written
```

<!-- expect: in shapes; dark; mean > 0.02 -->
```json
{ "type": "rect", "origin": [213, 548.7, 227], "edge_u": [0, 0, 105], "edge_v": [130, 0, 0], "material": "lamp" }
```

<!-- expect: in top; from scenes/cornell.json -->
```json
"image": { "width": 512, "height": 512, "spp": 63 }
```

<!-- expect: skip: a made-up option -->
```sh
franja render scenes/cornell.json -o x.png --no-such-option 3
```

<!-- expect: wobbles -->
```sh
echo unknown
```

<!-- expect: stdout fine -->
```sh
echo all-fine
```

<!-- expect: stdout stray -->

Text, and no example after the annotation.
MD

cat >"$T/bad.1" <<'MAN'
.TH BAD 1
.SH EXAMPLES
.nf
franja \-\-version
.fi
MAN

sh tests/it_docs.sh "$T/bad.md" "$T/bad.1" >"$T/out" 2>&1
rc=$?
check "it_docs.sh exits non-zero on the broken examples" test $rc -ne 0

# line TEXT: the line of bad.md where TEXT first appears.
line() { grep -nF -e "$1" "$T/bad.md" | head -n 1 | cut -d: -f1; }
# expect PLACE TEXT: a failure naming PLACE (bad.md:LINE or bad.1:LINE)
# with TEXT.
expect() {
    grep -F -- "FAIL: $T/$1:" "$T/out" | grep -qF -- "$2" && ok ||
        bad "no failure for $1 with '$2'; it_docs.sh said: $(grep -F "$T/$1:" "$T/out" | head -n 3)"
}
# fence TEXT: bad.md:LINE of the opening fence of the example whose first
# line has TEXT.
fence() { echo "bad.md:$(($(line "$1") - 1))"; }
expect "$(fence 'echo unannotated')" "has no annotation"
expect "$(fence 'echo nothing-claimed')" "says nothing the example shows"
expect "$(fence 'false')" "exit status 1"
expect "$(fence 'echo goodbye')" "stdout lacks 'hello there'"
expect "$(fence 'true')" "should fail with 'no such scene' but exits 0"
expect "$(fence 'bin/franja render scenes/cornell.json --samples 4')" "standard error lacks 'no such scene'"
expect "$(fence 'echo not-written')" "did not create made.txt"
expect "$(fence '"type": "rect"')" "expected > 0.02"
expect "$(fence '"spp": 63')" "not the same as in scenes/cornell.json"
expect "bad.md:$(line "--no-such-option")" "has no option --no-such-option"
expect "$(fence 'echo unknown')" "unknown check 'wobbles'"
expect "bad.md:$(line 'Text, and no example')" "is not directly before a fenced example"
expect bad.1:3 "has no annotation"
# The good example passes.
grep -F "$(fence 'echo all-fine')" "$T/out" >"$T/good"
check "the good example passes: $(cat "$T/good")" test ! -s "$T/good"
summary
