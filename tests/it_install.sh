#!/bin/sh
# it_install.sh -- tests make install and make uninstall into a DESTDIR.
#
# make install / make uninstall into a staging DESTDIR: the
# programs run from where they are installed (franja finds the installed
# worker), man finds the pages, bash completion offers the commands, the
# options and the scene files, and uninstall leaves no file behind.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need make man bash
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
unset MAKEFLAGS MFLAGS MAKELEVEL
D="$T/stage"
P=/opt/franja-test
R="$D$P"

make -s --no-print-directory install DESTDIR="$D" PREFIX="$P" >"$T/log" 2>&1 ||
    bad "make install failed: $(tail -n 3 "$T/log")"
for f in bin/franja bin/franja-worker share/man/man1/franja.1 share/man/man1/franja-worker.1 \
    share/man/man5/franja-hosts.5 share/bash-completion/completions/franja \
    share/bash-completion/completions/franja-worker; do
    [ -s "$R/$f" ] && ok || bad "make install did not install $P/$f"
done
[ -x "$R/bin/franja" ] && [ -x "$R/bin/franja-worker" ] && ok || bad "installed programs are not executable"
# Nothing outside the prefix.
out=$(find "$D" ! -type d | grep -v "^$R/")
[ -z "$out" ] && ok || bad "make install wrote outside PREFIX: $out"

# The installed programs run, and report the build's version.
v=$("$R/bin/franja" --version 2>&1) && ok || bad "installed franja --version failed: $v"
[ "$v" = "$(bin/franja --version)" ] && ok || bad "installed franja --version says '$v'"
case $v in franja*) ok ;; *) bad "franja --version: '$v'" ;; esac
w=$("$R/bin/franja-worker" --version 2>&1) && ok || bad "installed franja-worker --version failed: $w"
# ... and the installed franja renders with the installed worker (the one
# beside it: bin/ is not on PATH, and not next to it).
mkdir "$T/cwd"
cp scenes/cornell.json "$T/cwd/"
(cd "$T/cwd" && env PATH=/usr/bin:/bin "$R/bin/franja" render cornell.json -o c.ppm --size 16x16 --spp 1 -j 2) \
    >"$T/out" 2>&1 && [ -s "$T/cwd/c.ppm" ] && ok || bad "the installed franja does not render: $(tail -n 3 "$T/out")"

# man finds every page under the installed prefix.
for page in franja franja-worker franja-hosts; do
    where=$(man -M "$R/share/man" -w "$page" 2>&1)
    case $where in "$R"/share/man/man*/"$page".[15]) ok ;; *) bad "man -M does not find $page: $where" ;; esac
done
MANPATH="$R/share/man" MANWIDTH=80 man -P cat franja 2>/dev/null | grep -q "^SYNOPSIS" && ok ||
    bad "MANPATH=$P/share/man man franja shows no SYNOPSIS"

# Bash completion, as bash-completion would load it.
mkdir -p "$T/sc/sub"
: >"$T/sc/room.json"; : >"$T/sc/shot.glb"; : >"$T/sc/notes.txt"; : >"$T/sc/room.fbin"
comp() { # comp WORDS...: what completing the last word offers, sorted, one a line
    (cd "$T/sc" && PATH="$R/bin:/usr/bin:/bin" bash --norc --noprofile -c '
        . "$0/share/bash-completion/completions/franja" || exit 1
        COMP_WORDS=("$@"); COMP_CWORD=$(($# - 1))
        f=$(complete -p "$1" | sed -n "s/.*-F \([^ ]*\).*/\1/p")
        [ -n "$f" ] || { echo "no completion for $1" >&2; exit 1; }
        $f; printf "%s\n" "${COMPREPLY[@]}" | sort' "$R" "$@")
}
has() { # has WHAT LIST WORD...: each WORD is a line of LIST
    what=$1 list=$2; shift 2
    for w in "$@"; do printf '%s\n' "$list" | grep -qxF -- "$w" && ok || bad "$what: '$w' not offered (got: $(echo $list))"; done
}
hasnt() {
    what=$1 list=$2; shift 2
    for w in "$@"; do printf '%s\n' "$list" | grep -qxF -- "$w" && bad "$what: '$w' offered" || ok; done
}
c=$(comp franja "")
has "franja <TAB>" "$c" render compile stitch hosts deploy help version
c=$(comp franja re)
[ "$c" = render ] && ok || bad "franja re<TAB> gives '$c', not render"
c=$(comp franja render --s)
has "franja render --s<TAB>" "$c" --spp --size --slab-rows --slurm
hasnt "franja render --s<TAB>" "$c" --scene
# Every option of render's --help is offered.
for o in $(bin/franja render --help | grep -oE -- '^  +--?[A-Za-z][-A-Za-z]*' | tr -d ' '); do
    has "franja render -<TAB>" "$(comp franja render -)" "$o"
done
c=$(comp franja render "")
has "franja render <TAB>" "$c" room.json shot.glb room.fbin sub
hasnt "franja render <TAB>" "$c" notes.txt
c=$(comp franja compile "")
has "franja compile <TAB>" "$c" room.json shot.glb
hasnt "franja compile <TAB>" "$c" room.fbin notes.txt
has "franja render --tonemap <TAB>" "$(comp franja render x.json --tonemap "")" none filmic
has "franja render --progress <TAB>" "$(comp franja render x.json --progress "")" auto json
c=$(comp franja stitch "")
has "franja stitch <TAB>" "$c" sub
hasnt "franja stitch <TAB>" "$c" room.json
has "franja hosts <TAB>" "$(comp franja hosts "")" check list
has "franja hosts check --<TAB>" "$(comp franja hosts check --)" --hosts --timeout --slurm
has "franja-worker --<TAB>" "$(comp franja-worker --)" --scene --rows --format
has "franja-worker --format <TAB>" "$(comp franja-worker --format "")" pf ppm8 ppm16

# Uninstall removes every installed file, and only those.
: >"$R/bin/someone-elses"
make -s --no-print-directory uninstall DESTDIR="$D" PREFIX="$P" >"$T/log" 2>&1 ||
    bad "make uninstall failed: $(tail -n 3 "$T/log")"
left=$(find "$D" ! -type d)
[ "$left" = "$R/bin/someone-elses" ] && ok || bad "after make uninstall: '$left' (expected only bin/someone-elses)"
summary
