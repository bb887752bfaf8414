#!/bin/sh
# it_guide.sh -- tests make docs builds the guide and API pages, links intact.
#
# make docs: the user guide (pandoc) and the API
# documentation (Doxygen) are built; the guide has a page per README and
# per manual page, each man page's page has every section of the page
# (.SH), each README's page every heading, and every link of the guide
# leads somewhere: a page of the guide and an id on it, a file of the
# repository, or the API documentation.  The link checker itself must see
# a planted broken link and a planted missing anchor.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need make pandoc doxygen awk
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
unset MAKEFLAGS MFLAGS MAKELEVEL
D="$T/docs"
G="$D/guide"
make -s --no-print-directory docs DOCDIR="$D" >"$T/log" 2>&1 && ok || bad "make docs failed: $(tail -n 5 "$T/log")"
[ -s "$D/html/index.html" ] && ok || bad "make docs made no API documentation ($D/html/index.html)"
grep -rqs "caller-owned, width" "$D/html" && ok || bad "the API documentation lacks pt_render_rows' contract"

# page SOURCE: the guide's page of a source (the bar of every page lists them).
page() {
    case $1 in
    README.md) echo index.html ;;
    */man/*) basename "$1" | sed 's/$/.html/' ;;
    common/FORMAT.md) echo format.html ;;
    tests/bench/README.md) echo bench.html ;;
    *) echo "$(dirname "$1").html" ;;
    esac
}
# text FILE: the page's text, tags removed, entities of quotes decoded.
text() { sed -e 's/<[^>]*>//g' -e 's/&quot;/"/g' -e "s/&#39;/'/g" -e 's/&amp;/\&/g' "$1"; }

for man in coordinator/man/*.[1-9]; do
    p="$G/$(page "$man")"
    [ -s "$p" ] || { bad "no guide page $p for $man"; continue; }
    ok
    sed -n 's/^\.SH *//p' "$man" | tr -d '"' >"$T/sections"
    [ -s "$T/sections" ] && ok || bad "$man has no .SH sections"
    while read -r sec; do
        grep -q "<h1[^>]*>$sec</h1>" "$p" && ok || bad "$p lacks the section $sec of $man"
    done <"$T/sections"
    # The options of the page's OPTIONS are there, by name.
    for o in $(grep -A1 '^\.TP' "$man" | sed -n 's/^\.B[IR]* *\(\\-\\-[a-z-]*\).*/\1/p' | sed 's/\\//g' | sort -u); do
        text "$p" | grep -qF -- "$o" && ok || bad "$p lacks the option $o"
    done
done
for md in README.md coordinator/README.md scenes/README.md docker/README.md common/FORMAT.md tests/bench/README.md; do
    p="$G/$(page "$md")"
    [ -s "$p" ] || { bad "no guide page $p for $md"; continue; }
    ok
    sed -n 's/^##* //p' "$md" | sed -e 's/`//g' -e 's/\*//g' | while read -r h; do
        text "$p" | grep -qF -- "$h" || echo "$h"
    done >"$T/lost"
    [ -s "$T/lost" ] && bad "$p lacks the headings of $md: $(cat "$T/lost")" || ok
done

# check_links DIR: prints "PAGE: TARGET" for each link or image of DIR's
# pages that leads nowhere; absolute URLs are not followed.
check_links() {
    for f in "$1"/*.html; do
        grep -oE '(href|src)="[^"]*"' "$f" | sed -E 's/^(href|src)="//; s/"$//' | while read -r t; do
            case $t in http:* | https:* | mailto:*) continue ;; esac
            file=${t%%#*} frag=
            case $t in *"#"*) frag=${t#*#} ;; esac
            target=$f
            [ -n "$file" ] && target="$1/$file"
            if [ ! -e "$target" ]; then
                echo "$(basename "$f"): $t"
            elif [ -n "$frag" ] && ! grep -q "id=\"$frag\"" "$target"; then
                echo "$(basename "$f"): $t (no id $frag)"
            fi
        done
    done
}
check_links "$G" >"$T/broken"
[ -s "$T/broken" ] && bad "links of the guide that lead nowhere: $(cat "$T/broken")" || ok
# The links are there to be checked: between pages, to anchors, to the
# man pages from the READMEs, to the API documentation, to images.
cat "$G"/*.html >"$T/all"
for want in 'href="coordinator.html"' 'href="franja.1.html"' 'href="franja-hosts.5.html"' 'href="#' \
    'href="scenes.html"' 'html/index.html"' 'src="[^"]*scenes/images/cornell.png"'; do
    grep -q "$want" "$T/all" && ok || bad "the guide has no link like $want"
done
# README's own links to the guide and the API documentation become links
# within the built documentation.
grep -q 'build/docs/guide/index.html' README.md && grep -q 'build/docs/html/index.html' README.md && ok ||
    bad "README.md does not say where the guide and the API documentation land"
grep -oE 'href="[^"]*"' "$G/index.html" | grep -q 'href="\.\./html/index.html"' && ok ||
    bad "the guide's index does not link to the API documentation beside it"

# The checker sees what it should.
mkdir "$T/plant"
printf '<a href="gone.html">x</a>\n<a href="b.html#nowhere">y</a>\n<a href="b.html#here">z</a>\n' >"$T/plant/a.html"
printf '<h1 id="here">b</h1>\n' >"$T/plant/b.html"
check_links "$T/plant" >"$T/found"
grep -q 'gone.html' "$T/found" && grep -q 'nowhere' "$T/found" && ! grep -q '#here' "$T/found" && ok ||
    bad "the link checker is wrong on planted links: $(cat "$T/found")"
summary
