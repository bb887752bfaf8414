# docex.awk -- pulls the examples and their expect annotations out of the
# documentation, for tests/it_docs.sh (which describes the annotations).
#
#   awk -v out=DIR -v first=N -f tests/support/docex.awk DOC
#
# For the k-th example (numbered from first) it writes DIR/k.where
# ("file:line" of the opening fence or .nf/.EX request), DIR/k.lang (the
# fence's language, or "roff"), DIR/k.checks (one check a line: its kind, a
# tab, its argument) and DIR/k.body (the example's text; for man pages with
# the roff escapes undone).  Misplaced annotations and unclosed blocks are
# reported as "file:line: what is wrong" lines in DIR/errors.  Prints the
# number of the next example.  Man pages are the files named *.1 to *.9.

function trim(s) { sub(/^[ \t]+/, "", s); sub(/[ \t]+$/, "", s); return s }

# Splits the text of one annotation into checks: "kind argument", several
# on a line separated by ';' outside double quotes, except that skip:, run
# and template take the rest of the line.
function add_checks(text, line,    kind, rest, i, c, q, arg) {
    text = trim(text)
    while (text != "") {
        kind = text
        sub(/[ \t;].*/, "", kind)
        rest = trim(substr(text, length(kind) + 1))
        if (kind ~ /^skip:?$/ || kind == "run" || kind == "template") {
            sub(/:$/, "", kind)
            pending = pending kind "\t" rest "\n"
            return
        }
        q = 0
        for (i = 1; i <= length(rest); i++) {
            c = substr(rest, i, 1)
            if (c == "\"") q = !q
            else if (c == ";" && !q) break
        }
        arg = trim(substr(rest, 1, i - 1))
        pending = pending kind "\t" arg "\n"
        text = trim(substr(rest, i + 1))
    }
}

function problem(msg) { print FILENAME ":" FNR ": " msg >> (out "/errors") }

function open_example(lang) {
    k = n++
    print FILENAME ":" FNR > (out "/" k ".where"); close(out "/" k ".where")
    print lang > (out "/" k ".lang"); close(out "/" k ".lang")
    printf "%s", pending > (out "/" k ".checks"); close(out "/" k ".checks")
    printf "" > (out "/" k ".body")
    pending = ""
    inblock = 1
    start = FNR
}

function close_example() {
    close(out "/" k ".body")
    inblock = 0
}

# Undoes the roff escapes an example may use.
function unroff(s) {
    gsub(/\\-/, "-", s)
    gsub(/\\\(dq/, "\"", s)
    gsub(/\\\(aq/, "'", s)
    gsub(/\\&/, "", s)
    gsub(/\\f[BIRP]/, "", s)
    gsub(/\\e/, "\\", s)
    gsub(/\\\\/, "\\", s)
    return s
}

BEGIN { n = first + 0 }

FNR == 1 { roff = FILENAME ~ /\.[1-9]$/ }

roff && inblock {
    if ($0 ~ /^\.(fi|EE)([ \t]|$)/) { close_example(); next }
    if ($0 ~ /^\.\\"/ || $0 ~ /^\.[A-Za-z]/) next
    print unroff($0) >> (out "/" k ".body")
    next
}

roff {
    if ($0 ~ /^\.\\"[ \t]*expect:/) {
        t = $0; sub(/^\.\\"[ \t]*expect:/, "", t); add_checks(t, FNR); aline = FNR; next
    }
    if ($0 ~ /^\.(nf|EX)([ \t]|$)/) { open_example("roff"); next }
    if (pending != "" && $0 !~ /^[ \t]*$/) {
        problem("the expect annotation of line " aline " is not directly before an .nf or .EX block")
        pending = ""
    }
    next
}

inblock {
    if (substr(trim($0), 1, length(fence)) == fence && trim($0) ~ /^(`+|~+)$/) { close_example(); next }
    print $0 >> (out "/" k ".body")
    next
}

/^[ \t]*(```|~~~)/ {
    t = trim($0)
    fence = t; sub(/[^`~].*/, "", fence)
    lang = trim(substr(t, length(fence) + 1)); sub(/[ \t{].*/, "", lang)
    open_example(lang == "" ? "none" : lang)
    next
}

/^[ \t]*<!--[ \t]*expect:/ {
    if ($0 !~ /-->[ \t]*$/) { problem("an expect annotation must end with --> on its own line"); next }
    t = $0; sub(/^[ \t]*<!--[ \t]*expect:/, "", t); sub(/-->[ \t]*$/, "", t)
    add_checks(t, FNR); aline = FNR
    next
}

/^[ \t]*$/ { next }

pending != "" {
    problem("the expect annotation of line " aline " is not directly before a fenced example")
    pending = ""
}

END {
    if (inblock) problem("the example opened at line " start " is not closed")
    if (pending != "") problem("the expect annotation of line " aline " is before no example")
    print n
}
