#!/bin/sh
# build.sh -- the user guide as HTML.
#
# build.sh OUTDIR APIDIR: the project's Markdown documents and its manual
# pages as HTML pages in OUTDIR, each with a bar linking them
# all, links between them pointing at their pages (links.lua).  APIDIR is
# where the API documentation's index.html is (Doxygen; make docs).  Run
# from the repository's root (make docs, make guide).  Needs pandoc.
set -eu
out=${1:?usage: build.sh OUTDIR APIDIR}
api=${2:?usage: build.sh OUTDIR APIDIR}
command -v pandoc >/dev/null || { echo "build.sh: pandoc is missing (make deps installs it)" >&2; exit 1; }
mkdir -p "$out"
root=$(realpath --relative-to="$out" .)
apirel=$(realpath -m --relative-to="$out" "$api")/index.html

# SOURCE PAGE TITLE, in the order of the bar.
pages() {
    cat <<'LIST'
README.md index.html Franja
coordinator/README.md coordinator.html The coordinator
scenes/README.md scenes.html Scenes
common/FORMAT.md format.html The binary scene format
docker/README.md docker.html Builds for other systems
tests/bench/README.md bench.html Benchmarks
coordinator/man/franja.1 franja.1.html franja(1)
coordinator/man/franja-worker.1 franja-worker.1.html franja-worker(1)
coordinator/man/franja-hosts.5 franja-hosts.5.html franja-hosts(5)
LIST
}
map=$(pages | awk '{printf "%s%s=%s", (NR > 1 ? " " : ""), $1, $2}')
{
    echo '<nav class="guide-bar">'
    pages | while read -r src page title; do
        printf '<a href="%s">%s</a>\n' "$page" "$title"
    done
    printf '<a href="%s">API reference</a>\n' "$apirel"
    echo '</nav>'
} >"$out/.bar.html"
pages | while read -r src page title; do
    case $src in *.md) from=gfm ;; *) from=man ;; esac
    pandoc -f "$from" -t html5 --standalone --wrap=none --toc --toc-depth=2 --lua-filter=coordinator/guide/links.lua \
        --metadata pagetitle="Franja: $title" -M guide_src="$src" -M guide_map="$map" -M guide_root="$root" \
        -M guide_api="$apirel" --include-before-body="$out/.bar.html" -o "$out/$page" "$src"
done
rm -f "$out/.bar.html"
echo "user guide: $out/index.html"
