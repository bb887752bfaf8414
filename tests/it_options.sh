#!/bin/sh
# it_options.sh -- tests help texts, man pages and README agree on options.
#
# One list of options: `franja COMMAND --help`, `franja
# --help`, `franja-worker --help`, franja(1), franja-worker(1) and the
# option tables of README.md name the same options with the same defaults.
#
# From the help texts (what the programs print, whatever parses their
# command line): every option line "  -x ARG   what ... (default D)" and
# every option named anywhere.  Each option line must have a .TP entry in
# the OPTIONS of the man page and a row in the README's table; each entry
# and row must name an option the program has; where the help gives a
# default D (the text after "default" or "default:" up to ";" or ")"), the
# man entry says "default D" too and the README's default column is D, and
# where it gives none, neither does.  The options named in franja --help
# and in the SYNOPSIS sections must exist as well, and franja --help and
# the SYNOPSIS of franja(1) and franja-worker(1) list every option.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need awk
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# help_lines: "OPTION<TAB>DEFAULT" for the option lines of a help text on
# stdin (DEFAULT empty when none is given).
help_lines() {
    awk '
    function out() {
        if (opt == "") return
        d = ""
        if (match(desc, /default:? [^;)]*/)) { d = substr(desc, RSTART, RLENGTH); sub(/^default:? /, "", d) }
        gsub(/[ \t]+/, " ", d); sub(/[ .]+$/, "", d)
        print opt "\t" d
        opt = ""
    }
    /^  +--?[A-Za-z]/ { out(); opt = $1; desc = $0; next }
    /^      +[^ -]/ && opt != "" { desc = desc " " $0; next }
    { out() }
    END { out() }'
}

# named: every option token of a text on stdin, one a line.
named() { grep -oE -- '(^|[^A-Za-z0-9-])--?[A-Za-z][-A-Za-z]*' | sed 's/^[^-]*//' | sort -u; }

# readme_rows HEADER: "OPTION<TAB>DEFAULT" for the README table whose first
# header cell is HEADER (the option's first word, the last cell).
readme_rows() {
    awk -F '|' -v h="$1" '
    $0 ~ "^\\| " h " \\|" { on = 1; next }
    on && /^\|---/ { next }
    on && /^\|/ {
        o = $2; gsub(/`/, "", o); sub(/^ +/, "", o); sub(/ .*/, "", o)
        d = $(NF - 1); gsub(/`/, "", d); gsub(/^ +| +$/, "", d)
        print o "\t" d; next }
    on { exit }' README.md
}

# compare_sets WHAT PROGRAM HELPLINES ALLNAMED MANPAGE README_HEADER
compare_sets() {
    what=$1 help=$3 all=$4 page=$5 header=$6
    awk -f tests/support/manopts.awk "$page" >"$T/man"
    grep -v '^synopsis' "$T/man" >"$T/man.opts"
    readme_rows "$header" >"$T/readme"
    [ -s "$T/readme" ] && ok || bad "README.md: no table with a header starting '| $header |'"
    while IFS="$(printf '\t')" read -r opt def; do
        entry=$(awk -F '\t' -v o="$opt" '$1 == o { print $2; exit }' "$T/man.opts")
        if [ -z "$entry" ]; then
            bad "$page: OPTIONS has no entry for $opt (in $what --help)"
        else
            mdef=$(printf '%s\n' "$entry" | awk '{ d = ""
                if (match($0, /default:? [^;)]*/)) { d = substr($0, RSTART, RLENGTH); sub(/^default:? /, "", d) }
                gsub(/[ \t]+/, " ", d); sub(/[ .]+$/, "", d); print d }')
            [ "$mdef" = "$def" ] && ok ||
                bad "$page: $opt: default '${mdef:-none}', but $what --help says '${def:-none}'"
        fi
        if ! grep -q "^$opt	" "$T/readme"; then
            bad "README.md: the $header table has no row for $opt (in $what --help)"
        else
            rdef=$(awk -F '\t' -v o="$opt" '$1 == o { print $2; exit }' "$T/readme")
            [ "$rdef" = "$def" ] && ok ||
                bad "README.md: $opt: default '${rdef:-none}' in the $header table, but $what --help says '${def:-none}'"
        fi
    done <"$help"
    cut -f1 "$T/man.opts" | while read -r opt; do
        grep -qx -- "$opt" "$all" || echo "$page: OPTIONS documents $opt, which $what does not have (not in its --help)"
    done >"$T/extra"
    cut -f1 "$T/readme" | while read -r opt; do
        grep -qx -- "$opt" "$all" || echo "README.md: the $header table lists $opt, which $what does not have"
    done >>"$T/extra"
    grep '^synopsis' "$T/man" | cut -f2 | sort -u | while read -r opt; do
        grep -qx -- "$opt" "$all" || echo "$page: SYNOPSIS names $opt, which $what does not have"
    done >>"$T/extra"
    if [ -s "$T/extra" ]; then
        while IFS= read -r l; do bad "$l"; done <"$T/extra"
    else
        ok
    fi
}

# --- franja ---
: >"$T/f.help"
for c in render compile hosts deploy stitch; do
    bin/franja $c --help >"$T/f.$c" 2>&1 || bad "franja $c --help exits non-zero"
    cat "$T/f.$c" >>"$T/f.help"
done
bin/franja --help >"$T/f.top" 2>&1 && ok || bad "franja --help exits non-zero"
cat "$T/f.top" "$T/f.help" | named >"$T/f.named"
help_lines <"$T/f.help" | sort -u >"$T/f.lines"
# An option given with two different defaults by two commands is ambiguous.
cut -f1 "$T/f.lines" | uniq -d >"$T/dups"
while read -r opt; do
    n=$(awk -F '\t' -v o="$opt" '$1 == o && $2 != ""' "$T/f.lines" | sort -u | wc -l)
    [ "$n" -le 1 ] || bad "franja: $opt has different defaults in different commands' --help"
done <"$T/dups"
# One line an option: the default any command gives.
sort -t "$(printf '\t')" -k1,1 -k2,2r "$T/f.lines" | awk -F '\t' '!seen[$1]++' >"$T/f.opts"
# What franja --help names must be options of its commands.
named <"$T/f.top" | while read -r opt; do
    case "$opt" in --help | --version | -h | -V) continue ;; esac
    cat "$T/f.help" | named | grep -qx -- "$opt" || echo "franja --help names $opt, which no command's --help describes"
done >"$T/top.extra"
if [ -s "$T/top.extra" ]; then while IFS= read -r l; do bad "$l"; done <"$T/top.extra"; else ok; fi
compare_sets franja franja "$T/f.opts" "$T/f.named" coordinator/man/franja.1 '`franja` option'
# ... and the top-level usage (franja --help) and franja(1)'s SYNOPSIS list
# every option of every command.
named <"$T/f.top" >"$T/top.named"
awk -f tests/support/manopts.awk coordinator/man/franja.1 | awk -F '\t' '$1 == "synopsis" { print $2 }' | sort -u >"$T/syn"
cut -f1 "$T/f.opts" | while read -r opt; do
    grep -qx -- "$opt" "$T/top.named" || echo "franja --help (the top-level usage) does not list $opt"
    grep -qx -- "$opt" "$T/syn" || echo "franja(1): the SYNOPSIS does not list $opt"
done >"$T/unlisted"
if [ -s "$T/unlisted" ]; then while IFS= read -r l; do bad "$l"; done <"$T/unlisted"; else ok; fi

# --- franja-worker ---
bin/franja-worker --help >"$T/w.help" 2>&1 || bad "franja-worker --help exits non-zero"
named <"$T/w.help" >"$T/w.named"
help_lines <"$T/w.help" >"$T/w.opts"
compare_sets franja-worker franja-worker "$T/w.opts" "$T/w.named" coordinator/man/franja-worker.1 '`franja-worker` option'
awk -f tests/support/manopts.awk coordinator/man/franja-worker.1 | awk -F '\t' '$1 == "synopsis" { print $2 }' | sort -u >"$T/wsyn"
cut -f1 "$T/w.opts" | while read -r opt; do
    grep -qx -- "$opt" "$T/wsyn" || echo "franja-worker(1): the SYNOPSIS does not list $opt"
done >"$T/wunlisted"
if [ -s "$T/wunlisted" ]; then while IFS= read -r l; do bad "$l"; done <"$T/wunlisted"; else ok; fi
summary
