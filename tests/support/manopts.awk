# manopts.awk -- the options a man page documents, for tests/it_options.sh.
#
#   awk -f tests/support/manopts.awk PAGE.1
#
# Prints "OPTION<TAB>TEXT" for each .TP entry of the OPTIONS section whose
# tag starts with an option (TEXT: the entry's words as plain text, roff
# fonts and escapes undone), then "synopsis<TAB>OPTION" for every option
# the SYNOPSIS names.

# The arguments of a request line, quotes grouping words.
function args(s, a,    n, q, c, i, cur) {
    n = 0; q = 0; cur = ""
    for (i = 1; i <= length(s); i++) {
        c = substr(s, i, 1)
        if (c == "\"") { q = !q; continue }
        if ((c == " " || c == "\t") && !q) { if (cur != "") a[++n] = cur; cur = ""; continue }
        cur = cur c
    }
    if (cur != "") a[++n] = cur
    return n
}

function plain(s) {
    gsub(/\\-/, "-", s); gsub(/\\\(dq/, "\"", s); gsub(/\\\(aq/, "'", s); gsub(/\\&/, "", s)
    gsub(/\\f[BIRP]/, "", s); gsub(/\\e/, "\\", s); gsub(/\\\\/, "\\", s)
    return s
}

# A line as text: font requests give their words (the alternating ones
# glued together), other requests nothing.
function text(line,    req, rest, a, n, i, out) {
    if (line !~ /^\./) return plain(line)
    req = line; sub(/[ \t].*/, "", req)
    rest = substr(line, length(req) + 1)
    n = args(rest, a)
    out = ""
    if (req ~ /^\.(B|I|SM|SB)$/) { for (i = 1; i <= n; i++) out = out (i > 1 ? " " : "") a[i]; return plain(out) }
    if (req ~ /^\.(BI|IB|BR|RB|IR|RI)$/) { for (i = 1; i <= n; i++) out = out a[i]; return plain(out) }
    return ""
}

function flush() {
    if (opt != "") { gsub(/[ \t]+/, " ", body); sub(/^ /, "", body); print opt "\t" body }
    opt = ""; body = ""
}

/^\.SH/ { flush(); section = $2; tag = 0; next }
section == "SYNOPSIS" {
    t = text($0)
    while (match(t, /(^|[^A-Za-z0-9-])--?[A-Za-z][-A-Za-z]*/)) {
        o = substr(t, RSTART, RLENGTH); sub(/^[^-]*/, "", o)
        print "synopsis\t" o
        t = substr(t, RSTART + RLENGTH)
    }
    next
}
section != "OPTIONS" { next }
/^\.TP/ { flush(); tag = 1; next }
tag {
    tag = 0
    t = text($0)
    if (t ~ /^--?[A-Za-z]/) { opt = t; sub(/[ \t=].*/, "", opt); body = "" }
    next
}
opt != "" { body = body " " text($0) }
END { flush() }
