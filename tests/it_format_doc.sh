#!/bin/sh
# it_format_doc.sh -- tests FORMAT.md against the format the code uses.
#
# FORMAT.md (the binary scene's specification) says the
# format version and the sections that the code writes and reads.
#
# From FORMAT.md: the version of its title, of its opening paragraph, of
# the header table, of reader rule 1 and the last of its version history;
# the section count of the layout diagram (with the table's size and the
# first section's offset), of the header table, of the section table's
# heading and id range, of reader rule 1, and the rows of the sections
# table (id, name, element size).  From the code: FBIN_VERSION (fbin.h),
# the sections' names in fbin.c's table, `franja-worker --version`, and
# the header and section table of a scene that franja compiles.  Every
# statement must be there and agree; a version or a section added to one
# side only fails here.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need awk od
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# find_src NAME: the source file NAME under common/ (wherever in it).
find_src() { find common -name "$1" -type f | head -n 1; }
DOC=$(find_src FORMAT.md)
FBIN_H=$(find_src fbin.h)
FBIN_C=$(find_src fbin.c)
for f in "$DOC" "$FBIN_H" "$FBIN_C"; do
    [ -n "$f" ] && [ -f "$f" ] || { bad "common/: FORMAT.md, fbin.h or fbin.c not found"; summary; exit 1; }
done

# said WHAT VALUE: VALUE was found in FORMAT.md for WHAT (else it is not said).
said() {
    [ -n "$2" ] && ok || bad "$DOC no longer says $1"
}
# agree WHAT A B: the doc's A equals the code's B.
agree() {
    [ "$2" = "$3" ] && ok || bad "$DOC: $1 is '$2', the code's is '$3'"
}

# --- the code ---
v_code=$(sed -n 's/^#define FBIN_VERSION \([0-9][0-9]*\).*/\1/p' "$FBIN_H")
[ -n "$v_code" ] && ok || bad "$FBIN_H: no FBIN_VERSION"
v_worker=$(bin/franja-worker --version | sed -n 's/.* scene-format \([0-9][0-9]*\).*/\1/p')
agree "FBIN_VERSION" "$v_code" "$v_worker"
# The sections' names, in id order, from fbin.c's table of sections.
awk '/^static const section_desc sections\[/ { on = 1; next } on && /^};/ { exit }
     on { if (match($0, /"[a-z_]+"/)) print substr($0, RSTART + 1, RLENGTH - 2) }' "$FBIN_C" >"$T/code_names"
n_code=$(wc -l <"$T/code_names" | tr -d ' ')
[ "$n_code" -gt 0 ] && ok || bad "$FBIN_C: no table of sections found"
# A compiled scene: version (byte 8), section count (byte 20), and each
# table entry's id and element size (entry k at 64 + 32 k).
bin/franja compile scenes/spheres.json -o "$T/s.fbin" >/dev/null 2>&1 || bad "franja compile scenes/spheres.json failed"
u32() { od -An -tu4 -j "$1" -N 4 "$T/s.fbin" | tr -d ' '; }
v_file=$(u32 8)
n_file=$(u32 20)
agree "the version of a compiled scene" "$v_code" "$v_file"
agree "the section count of fbin.c's table" "$n_code" "$n_file"
k=0
: >"$T/file_rows"
while [ "$k" -lt "${n_file:-0}" ]; do
    printf '%s %s\n' "$(u32 $((64 + 32 * k)))" "$(u32 $((68 + 32 * k)))" >>"$T/file_rows"
    k=$((k + 1))
done

# --- FORMAT.md: the version ---
v=$(sed -n '1s/^# .*format version \([0-9][0-9]*\)$/\1/p' "$DOC")
said "the version in its title" "$v"
agree "the version in its title" "$v" "$v_code"
v=$(sed -n 's/.*byte offsets of version \([0-9][0-9]*\) .*/\1/p' "$DOC" | head -n 1)
said "'the byte offsets of version N'" "$v"
agree "the version of its opening paragraph" "$v" "$v_code"
v=$(sed -n 's/^| 8 *| u32 *| format version, `\([0-9][0-9]*\)` |$/\1/p' "$DOC")
said "the version in the header table" "$v"
agree "the version in the header table" "$v" "$v_code"
v=$(sed -n 's/^1\. At least 64 bytes; the magic; version \([0-9][0-9]*\);.*/\1/p' "$DOC")
said "the version in reader rule 1" "$v"
agree "the version in reader rule 1" "$v" "$v_code"
# The version history: "Version history: 1, ...; 2, ...; N, ..." to the
# end of its paragraph; its last version is the format's.
v=$(awk '/Version history:/ { on = 1 } on && /^$/ { exit } on { printf "%s ", $0 }' "$DOC" |
    sed 's/.*Version history://' | grep -oE '(^|;) *[0-9]+, ' | tr -dc '0-9\n' | tail -n 1)
said "a version history" "$v"
agree "the last version of the version history" "$v" "$v_code"

# --- FORMAT.md: the sections ---
n=$(sed -n 's/^offset 64 *section table, \([0-9][0-9]*\) entries of 32 bytes (\([0-9][0-9]*\) bytes)$/\1 \2/p' "$DOC")
said "the section table in the layout diagram" "$n"
agree "the section count in the layout diagram" "${n%% *}" "$n_file"
agree "the section table's size in the layout diagram" "${n##* }" "$((32 * n_file))"
first=$(sed -n 's/^offset \([0-9][0-9]*\) *section 1 (settings).*/\1/p' "$DOC")
said "the offset of section 1 in the layout diagram" "$first"
agree "the offset of section 1" "$first" "$(((64 + 32 * n_file + 63) / 64 * 64))"
n=$(sed -n 's/^| 20 *| u32 *| number of sections, `\([0-9][0-9]*\)` |$/\1/p' "$DOC")
said "the section count in the header table" "$n"
agree "the section count in the header table" "$n" "$n_file"
n=$(sed -n 's/^### Section table (\([0-9][0-9]*\) entries of 32 bytes.*/\1/p' "$DOC")
said "the section count in the section table's heading" "$n"
agree "the section count in the section table's heading" "$n" "$n_file"
n=$(sed -n 's/^| 0 *| u32 | section id, 1 to \([0-9][0-9]*\);.*/\1/p' "$DOC")
said "the range of section ids" "$n"
agree "the last section id" "$n" "$n_file"
n=$(sed -n 's/^ *64; \([0-9][0-9]*\) sections; .*/\1/p' "$DOC")
said "the section count in reader rule 1" "$n"
agree "the section count in reader rule 1" "$n" "$n_file"
# The sections table: "| id | name | `type` | size | count |" rows under "### Sections".
awk '/^### Sections$/ { on = 1; next } on && /^#/ { exit }
     on && /^\| *[0-9]+ *\|/ { split($0, f, "|"); gsub(/[ `]/, "", f[2]); gsub(/[ `]/, "", f[3]); gsub(/ /, "", f[5]);
                             print f[2], f[3], f[5] }' "$DOC" >"$T/doc_rows"
agree "the number of rows of the sections table" "$(wc -l <"$T/doc_rows" | tr -d ' ')" "$n_file"
awk '{ print $1, $3 }' "$T/doc_rows" >"$T/doc_sizes"
cmp -s "$T/doc_sizes" "$T/file_rows" && ok ||
    bad "$DOC: the sections table's ids and element sizes differ from a compiled scene's table: " \
        "$(diff "$T/doc_sizes" "$T/file_rows" | grep '^[<>]' | tr '\n' ' ')"
awk '{ print $2 }' "$T/doc_rows" >"$T/doc_names"
cmp -s "$T/doc_names" "$T/code_names" && ok ||
    bad "$DOC: the sections table's names differ from $FBIN_C's: $(diff "$T/doc_names" "$T/code_names" | grep '^[<>]' | tr '\n' ' ')"
summary
