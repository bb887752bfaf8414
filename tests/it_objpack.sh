#!/bin/sh
# it_objpack.sh -- compiles every OBJ file of Debian's assimp-testmodels.
#
# Each OBJ file of assimp-testmodels (models/OBJ and models/invalid) is
# copied with the files beside it into a folder of its own (a scene reads
# only its own folder) and compiled as the one mesh of a scene.  The files
# scenes/README.md lists as refused must fail, with the reason it gives and
# a file:line or file: message; every other one must compile.  Names with
# spaces and missing MTL files are checked for what they become.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
F=bin/franja
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
M=/usr/share/assimp/models
if [ ! -d "$M/OBJ" ]; then
    bad "assimp-testmodels is not installed (tests/install-deps.sh)"
    summary
    exit
fi

# The refusals, as scenes/README.md lists them: file and message fragment.
refused() {
    case "$1" in
    box_UTF16BE) echo "box_UTF16BE.obj: UTF-16 text" ;;
    empty | point_cloud | testline | testpoints) echo "$1.obj: no faces" ;;
    malformed) echo "malformed.obj:23: vertex index 12 out of range" ;;
    malformed2) echo "malformed2.obj:23: a face needs at least 3 corners, got 0" ;;
    number_formats) echo "number_formats.obj:11: expected a finite number for v" ;;
    *) return 1 ;;
    esac
}

n_load=0 n_refused=0
for obj in "$M"/OBJ/*.obj "$M"/invalid/*.obj; do
    name=$(basename "$obj" .obj)
    d="$T/$name"
    mkdir "$d"
    find "$(dirname "$obj")" -maxdepth 1 -type f ! -name '*.obj' -exec cp {} "$d/" \;
    cp "$obj" "$d/"
    cat >"$d/scene.json" <<EOF
{ "image": { "width": 16, "height": 16, "spp": 1 },
  "camera": { "position": [0, 1, -6], "target": [0, 0, 0], "fov": 40 },
  "materials": { "grey": { "type": "lambert", "albedo": [0.8, 0.8, 0.8] } },
  "lights": [ { "type": "point", "position": [0, 4, -3], "intensity": [20, 20, 20] } ],
  "shapes": [ { "type": "mesh", "file": "$name.obj" } ] }
EOF
    if want=$(refused "$name"); then
        expect_error "$name.obj refused" "$want" $F compile "$d/scene.json" -o "$d/scene.fbin" &&
            n_refused=$((n_refused + 1))
    elif $F compile "$d/scene.json" -o "$d/scene.fbin" >"$d/out" 2>"$d/err"; then
        ok
        n_load=$((n_load + 1))
    else
        bad "$name.obj: not compiled: $(cat "$d/err")"
    fi
done
[ "$n_load" -eq 17 ] && [ "$n_refused" -eq 8 ] && ok || bad "17 load and 8 are refused, got $n_load and $n_refused"

# Names with spaces are one name: the box gets the MTL's colour, not the
# default material, and nothing is warned.
for name in box_mat_with_spaces space_in_material_name; do
    [ -s "$T/$name/scene.fbin" ] && [ ! -s "$T/$name/err" ] && ok || bad "$name: warnings: $(cat "$T/$name/err")"
done
sed 's/"mesh", "file"/"mesh", "material": "grey", "file"/' "$T/box_mat_with_spaces/scene.json" >"$T/box_mat_with_spaces/grey.json"
a=$(sed -n 's/.*: scene \([0-9a-f]*\),.*/\1/p' "$T/box_mat_with_spaces/out")
b=$($F compile "$T/box_mat_with_spaces/grey.json" -o "$T/grey.fbin" 2>&1 | sed -n 's/.*: scene \([0-9a-f]*\),.*/\1/p')
[ -n "$a" ] && [ -n "$b" ] && [ "$a" != "$b" ] && ok || bad "the named material is the MTL's (scenes differ: '$a' '$b')"

# A missing mtllib file: a warning naming the file and line, the default
# material, a scene.
grep -q "warning: .*cube_mtllib_after_g.obj:2: mtllib: .*cube_mtllib_after_g.mat does not exist" \
    "$T/cube_mtllib_after_g/err" && ok || bad "missing mtllib: $(cat "$T/cube_mtllib_after_g/err")"
grep -q "warning: .*cube_usemtl.obj:21: usemtl: 1 material name defined in no mtllib file" "$T/cube_usemtl/err" &&
    ok || bad "undefined usemtl: $(cat "$T/cube_usemtl/err")"
# Error messages quote no bytes of the file: the malformed number is not
# repeated.
$F compile "$T/number_formats/scene.json" -o "$T/x.fbin" >/dev/null 2>"$T/nf.err"
grep -q 'e2' "$T/nf.err" && bad "the malformed number is quoted: $(cat "$T/nf.err")" || ok
summary
