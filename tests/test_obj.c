/* test_obj.c -- the OBJ/MTL reader (coordinator/compile/obj.h): corner forms, negative
 * indices, polygons (convex and concave), groups, several materials per
 * file, MTL statements and their mapping to Franja materials, and errors
 * that name the file, the line and what was expected. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "compile/obj.h"

static int parse(const char *text, mesh_data *m, fr_error *err)
{
    return obj_parse(text, strlen(text), "t.obj", NULL, NULL, NULL, m, err);
}

/* Parsing must fail with a message containing `want`. */
static void bad(const char *text, const char *want)
{
    mesh_data m;
    fr_error err = {{0}};
    int rc = parse(text, &m, &err);
    CHECK(rc < 0, "accepted: %s", text);
    if (rc == 0)
        mesh_data_free(&m);
    else
        CHECK(strstr(err.msg, want) != NULL, "message \"%s\" lacks \"%s\"", err.msg, want);
}

/* Warnings received through an obj_warn sink. */
typedef struct {
    int n;
    char last[512];
} warnings;

static void note_warning(void *user, const char *msg)
{
    warnings *w = user;
    w->n++;
    snprintf(w->last, sizeof w->last, "%s", msg);
}

static double tri_area2(const mesh_data *m, uint32_t t, vec3 n)
{
    vec3 a = m->pos[m->tri[t][0]], b = m->pos[m->tri[t][1]], c = m->pos[m->tri[t][2]];
    return v3_dot(v3_cross(v3_sub(b, a), v3_sub(c, a)), n);
}

static void test_basic(void)
{
    mesh_data m;
    fr_error err;
    CHECK(parse("# a triangle\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", &m, &err) == 0, "%s", err.msg);
    CHECK(m.n_tri == 1 && m.n_vert == 3 && !m.nrm && !m.uv && m.tri_flags[0] == 0, "plain triangle");
    mesh_data_free(&m);

    /* Negative indices count back from the last vertex defined so far. */
    CHECK(parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nf -4 -3 -1\n", &m, &err) == 0, "%s", err.msg);
    CHECK(m.n_tri == 2 && m.tri[0][0] == m.tri[1][0] && m.tri[0][1] == m.tri[1][1], "negative indices resolve");
    CHECK(m.n_vert == 4 && m.pos[m.tri[1][2]].x == 5.0f, "relative to the count so far");
    mesh_data_free(&m);

    /* CRLF, tabs, comments, w and vertex colours, 1-3 component vt. */
    CHECK(parse("v\t0 0 0 1\r\nv 1 0 0 0.5 0.5 0.5\r\nv 0 1 0 # corner\r\nvt 0.5\nvt 1 0 0\nvt 0 1\n"
                "f 1/1 2/2 3/3\r\n\n",
                &m, &err) == 0,
          "%s", err.msg);
    CHECK(m.n_tri == 1 && m.uv && m.tri_flags[0] == FR_TRI_UVS && m.uv[m.tri[0][0]].u == 0.5f &&
              m.uv[m.tri[0][2]].v == 1.0f,
          "texture coordinates");
    mesh_data_free(&m);
}

static void test_corners(void)
{
    mesh_data m;
    fr_error err;
    const char *text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
                       "f 1/1/1 2/2/1 3/3/1\n"    /* all three */
                       "f 1/1/1 3/3/1 4/4/1\n"    /* shares two corners with the first */
                       "f 1//1 2//1 3//1\n"       /* normals only: new vertices */
                       "f 1 3 4\n";               /* positions only */
    CHECK(parse(text, &m, &err) == 0, "%s", err.msg);
    CHECK(m.n_tri == 4, "four faces: %u", m.n_tri);
    CHECK(m.tri_flags[0] == (FR_TRI_NORMALS | FR_TRI_UVS) && m.tri_flags[1] == (FR_TRI_NORMALS | FR_TRI_UVS) &&
              m.tri_flags[2] == FR_TRI_NORMALS && m.tri_flags[3] == 0,
          "flags %d %d %d %d", m.tri_flags[0], m.tri_flags[1], m.tri_flags[2], m.tri_flags[3]);
    CHECK(m.tri[0][0] == m.tri[1][0] && m.tri[0][2] == m.tri[1][1], "same (v, vt, vn) corners share a vertex");
    CHECK(m.tri[2][0] != m.tri[0][0], "a different corner triple is another vertex");
    CHECK(m.n_vert == 4 + 3 + 3, "vertices: %u", m.n_vert);
    CHECK(m.nrm && m.nrm[m.tri[0][0]].z == 1.0f && v3_is_zero(m.nrm[m.tri[3][0]]), "normals (zero where absent)");
    mesh_data_free(&m);
}

static void test_polygons(void)
{
    mesh_data m;
    fr_error err;
    /* Convex pentagon: a fan from the first corner, in file order. */
    CHECK(parse("v 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 2 0\nv -1 1 0\nf 1 2 3 4 5\n", &m, &err) == 0, "%s", err.msg);
    CHECK(m.n_tri == 3 && m.tri[0][0] == m.tri[1][0] && m.tri[1][0] == m.tri[2][0], "pentagon fan: %u", m.n_tri);
    mesh_data_free(&m);
    /* Concave: an L of area 3 (counter-clockwise seen from +z) whose fan
     * from the first corner would leave the shape. */
    const char *arrow = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n"
                        "f 4 5 6 1 2 3\n";   /* starts at the reflex corner (1, 1) */
    CHECK(parse(arrow, &m, &err) == 0, "%s", err.msg);
    double sum = 0.0;
    int all_ccw = 1;
    for (uint32_t t = 0; t < m.n_tri; t++) {
        double a = tri_area2(&m, t, v3(0, 0, 1));
        sum += a;
        all_ccw &= a > 0.0;
    }
    CHECK(m.n_tri == 4 && all_ccw && sum == 6.0, "concave L: %u triangles, doubled area %g, all ccw %d", m.n_tri, sum,
          all_ccw);
    mesh_data_free(&m);
    /* Clockwise concave polygon keeps its (clockwise) winding. */
    CHECK(parse("v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 6 5 4 3 2 1\n", &m, &err) == 0, "%s",
          err.msg);
    sum = 0.0;
    int all_cw = 1;
    for (uint32_t t = 0; t < m.n_tri; t++) {
        double a = tri_area2(&m, t, v3(0, 0, 1));
        sum += a;
        all_cw &= a < 0.0;
    }
    CHECK(m.n_tri == 4 && all_cw && sum == -6.0, "clockwise L: doubled area %g", sum);
    mesh_data_free(&m);
    /* A polygon in a tilted plane. */
    CHECK(parse("v 0 0 0\nv 1 0 1\nv 1 1 1\nv 0 1 0\nf 1 2 3 4\n", &m, &err) == 0 && m.n_tri == 2, "tilted quad");
    mesh_data_free(&m);
}

/* Writes text into the file dir/name; its path is left in path[cap]. */
static void put_file(char *path, size_t cap, const char *dir, const char *name, const char *text)
{
    snprintf(path, cap, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) {
        CHECK(0, "%s: cannot create", path);
        return;
    }
    fputs(text, f);
    fclose(f);
}

static void test_groups_materials(void)
{
    char dir[] = "/tmp/franja-test-obj-XXXXXX";
    CHECK(mkdtemp(dir) != NULL, "mkdtemp");
    char path[256];
    put_file(path, sizeof path, dir, "a.mtl",
             "# materials\nnewmtl red\nKd 0.8 0.1 0.1\nKa 0.1 0.1 0.1\nmap_Kd red.png\n"
             "newmtl shiny\nKd 0.5 0.5 0.5\nKs 0.9 0.9 0.9\nNs 200\nillum 2\n"
             "newmtl lamp\nKd 0 0 0\nKe 4 4 3\n");
    put_file(path, sizeof path, dir, "b.mtl",
             "newmtl glass\nKd 0 0 0\nTf 0.9 0.9 1\nNi 1.45\nillum 7\nd 0.5\n"
             "newmtl mirror\nKs 0.95\nillum 3\n");
    put_file(path, sizeof path, dir, "m.obj",
             "mtllib a.mtl b.mtl\no thing\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
             "f 1 2 3\n"                                        /* before any usemtl: default */
             "g left\nusemtl red\nf 1 2 3\ng right top\nusemtl shiny\nf 2 4 3\n"
             "usemtl lamp\nf 1 2 4\ns 1\nusemtl glass\nf 1 3 4\nusemtl mirror\nf 3 2 1\nusemtl red\nf 4 3 2\n");
    mesh_data m;
    fr_error err;
    CHECK(obj_read(path, NULL, NULL, NULL, &m, &err) == 0, "%s", err.msg);
    CHECK(m.n_tri == 7, "faces in every group: %u", m.n_tri);
    const char *names[] = {"(default)", "red", "shiny", "lamp", "glass", "mirror", "red"};
    for (uint32_t t = 0; t < m.n_tri && t < 7; t++)
        CHECK(!strcmp(m.mats[m.tri_mat[t]].name, names[t]) && m.mats[m.tri_mat[t]].defined,
              "face %u: material %s, expected %s", t, m.mats[m.tri_mat[t]].name, names[t]);
    fr_material fm;
    mesh_data_material(&m.mats[m.tri_mat[1]], &fm);
    CHECK(fm.diffuse.x == 0.8f && v3_is_zero(fm.glossy) && fm.tex_diffuse == FR_NONE, "red: Lambert");
    mesh_data_material(&m.mats[m.tri_mat[2]], &fm);
    CHECK(fm.exponent == 200.0f && fm.glossy.x > 0.0f && v3_max(v3_add(fm.diffuse, fm.glossy)) <= 1.0f &&
              fm.glossy.x / fm.diffuse.x > 1.79f && fm.glossy.x / fm.diffuse.x < 1.81f,
          "shiny: Phong scaled to conserve energy (%g %g)", (double)fm.diffuse.x, (double)fm.glossy.x);
    mesh_data_material(&m.mats[m.tri_mat[3]], &fm);
    CHECK(fm.emission.x == 4.0f && fm.emission.z == 3.0f, "lamp: emission");
    mesh_data_material(&m.mats[m.tri_mat[4]], &fm);
    CHECK(fm.transmit.z == 1.0f && fm.ior == 1.45f, "glass: transmit %g ior %g", (double)fm.transmit.z,
          (double)fm.ior);
    mesh_data_material(&m.mats[m.tri_mat[5]], &fm);
    CHECK(fm.specular.x == 0.95f && v3_is_zero(fm.glossy), "mirror: specular");
    mesh_data_free(&m);

    /* A usemtl without a definition is kept, marked undefined, with its line. */
    put_file(path, sizeof path, dir, "m.obj", "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl nosuch\nf 1 2 3\n");
    CHECK(obj_read(path, NULL, NULL, NULL, &m, &err) == 0, "%s", err.msg);
    CHECK(m.n_tri == 1 && !m.mats[m.tri_mat[0]].defined && m.mats[m.tri_mat[0]].line == 5, "undefined material");
    mesh_data_free(&m);
    /* A missing MTL file is a warning naming its file and line; its names
     * stay undefined.  MTL errors name their file and line. */
    put_file(path, sizeof path, dir, "m.obj", "v 0 0 0\nmtllib missing.mtl\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n");
    warnings w = {0, ""};
    obj_warn sink = {note_warning, &w};
    CHECK(obj_read(path, NULL, NULL, &sink, &m, &err) == 0 && m.n_tri == 1 && !m.mats[m.tri_mat[0]].defined,
          "missing mtllib: %s", err.msg);
    CHECK(w.n == 1 && strstr(w.last, "m.obj:2: mtllib: ") && strstr(w.last, "missing.mtl does not exist"),
          "missing mtllib warned once: %d \"%s\"", w.n, w.last);
    mesh_data_free(&m);
    put_file(path, sizeof path, dir, "a.mtl", "newmtl x\nKd 1 1\n");
    put_file(path, sizeof path, dir, "m.obj", "mtllib a.mtl\n");
    CHECK(obj_read(path, NULL, NULL, NULL, &m, &err) < 0 && strstr(err.msg, "a.mtl:2:") && strstr(err.msg, "Kd"), "MTL error: %s",
          err.msg);
    /* Two MTL files of one OBJ defining one name: which was meant? */
    put_file(path, sizeof path, dir, "a.mtl", "newmtl red\nKd 0.8 0.1 0.1\n");
    put_file(path, sizeof path, dir, "b.mtl", "newmtl blue\nKd 0.1 0.1 0.8\nnewmtl red\nKd 0.9 0 0\n");
    put_file(path, sizeof path, dir, "m.obj", "mtllib a.mtl b.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
    CHECK(obj_read(path, NULL, NULL, NULL, &m, &err) < 0 && strstr(err.msg, "b.mtl:3:") && strstr(err.msg, "newmtl: the material is defined twice"),
          "one material name in two MTL files: %s", err.msg);
    const char *files[] = {"a.mtl", "b.mtl", "m.obj"};
    for (int i = 0; i < 3; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, files[i]);
        unlink(path);
    }
    rmdir(dir);
}

static void test_mtl_errors(void)
{
    struct { const char *text, *want; } cases[] = {
        {"Kd 1 1 1\n", "t.mtl:1: a material statement before any newmtl"},
        {"newmtl a\nKd 1 -1 1\n", "t.mtl:2: Kd: colours must be >= 0"},
        {"newmtl a\nNs abc\n", "t.mtl:2: expected a finite number"},
        {"newmtl a\nillum 2.5\n", "t.mtl:2: illum"},
        {"newmtl a\nnewmtl a\n", "t.mtl:2: newmtl: the material is defined twice"},
        {"newmtl a\nsparkle 3\n", "t.mtl:2: unknown MTL statement (expected"},
        {"newmtl a\nd 2\n", "t.mtl:2: d: expected a number in [0, 1]"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        mesh_data m;
        memset(&m, 0, sizeof m);
        fr_error err = {{0}};
        int rc = obj_parse_mtl(cases[i].text, strlen(cases[i].text), "t.mtl", &m, &err);
        CHECK(rc < 0 && strstr(err.msg, cases[i].want), "MTL \"%s\": %s", cases[i].text, rc < 0 ? err.msg : "accepted");
        mesh_data_free(&m);
    }
}

static void test_errors(void)
{
    bad("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "t.obj:4: vertex index 0 out of range");
    bad("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "t.obj:4: vertex index 4 out of range (3 defined so far)");
    bad("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 2 3\n", "t.obj:4: vertex index -4 out of range");
    bad("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/2 2/2 3/2\n", "t.obj:4: texture coordinate index 2 out of range");
    bad("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n", "t.obj:4: normal index 1 out of range");
    bad("v 0 0 0\nv 1 0 0\nf 1 2\n", "t.obj:3: a face needs at least 3 corners, got 2");
    bad("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", "t.obj:4: expected a face corner");
    bad("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 three\n", "t.obj:4: expected a face corner");
    bad("v 1 x 3\n", "t.obj:1: expected a finite number for v");
    bad("v 1 2\n", "t.obj:1: v: expected x y z [w] or x y z r g b, got 2 numbers");
    bad("v 1 2 nan\n", "t.obj:1: expected a finite number");
    bad("v 1 2 1e99\n", "t.obj:1: expected a finite number");
    bad("vn 1 2\n", "t.obj:1: vn: expected x y z");
    bad("vt\n", "t.obj:1: vt: expected u");
    bad("v 0 0 0 1 2\n", "t.obj:1: v: expected x y z [w] or x y z r g b, got 5 numbers");
    bad("v 0 0 0 1 2 3 4 5\n", "t.obj:1: v: too many numbers");
    bad("v 0 0 0 junk\n", "t.obj:1: expected a finite number for v");
    bad("# nothing\nv 0 0 0\n", "t.obj: no faces");
    bad("v 0 0 0\nfoo 1 2\n", "t.obj:2: unknown OBJ statement (expected");
    char longname[200] = "usemtl ";
    memset(longname + 7, 'a', 150);
    strcpy(longname + 157, "\n");
    bad(longname, "t.obj:1: usemtl: a material name longer than 127 bytes");
    bad("mtllib\n", "t.obj:1: mtllib: expected a file name");
    mesh_data m;
    fr_error err;
    const char nul[] = "v 0 0 0\nv 1 0 0\n\0v 0 1 0\nf 1 2 3\n";
    CHECK(obj_parse(nul, sizeof nul - 1, "t.obj", NULL, NULL, NULL, &m, &err) < 0 && strstr(err.msg, "t.obj:3: NUL byte"),
          "NUL byte: %s", err.msg);
    const char utf16[] = "\xfe\xff\0v\0 \0001\0\n";
    CHECK(obj_parse(utf16, sizeof utf16 - 1, "t.obj", NULL, NULL, NULL, &m, &err) < 0 &&
              strstr(err.msg, "t.obj: UTF-16 text"),
          "UTF-16: %s", err.msg);
    /* Ignored statements of the format are accepted. */
    CHECK(parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvp 0.5\nl 1 2\np 1\ns off\ncstype bezier\nf 1 2 3\n", &m, &err) == 0 &&
              m.n_tri == 1,
          "ignored statements: %s", err.msg);
    mesh_data_free(&m);
}

/* Material names are the rest of the line, blanks inside kept and those
 * around dropped, as Assimp and Blender read them (assimp-testmodels'
 * space_in_material_name.obj, box_mat_with_spaces.obj); an empty name is
 * a name too (Blender writes `newmtl ` for a nameless material). */
static void test_material_names(void)
{
    char dir[] = "/tmp/franja-test-obj-XXXXXX";
    CHECK(mkdtemp(dir) != NULL, "mkdtemp");
    char path[256];
    put_file(path, sizeof path, dir, "s.mtl",
             "\xef\xbb\xbfnewmtl Hard Shiny Plastic White\r\nKd 0.1 0.2 0.4\r\n"
             "newmtl   Material #25  \nKd 0.5 0.5 0.5\nnewmtl Hard Shiny\nKd 1 0 0\nnewmtl \nKd 0 1 0\n");
    put_file(path, sizeof path, dir, "s.obj",
             "mtllib s.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
             "usemtl  Hard Shiny Plastic White \r\nf 1 2 3\nusemtl Material #25\nf 1 2 3\n"
             "usemtl Hard Shiny\nf 1 2 3\nusemtl\nf 1 2 3\n");
    mesh_data m;
    fr_error err;
    warnings w = {0, ""};
    obj_warn sink = {note_warning, &w};
    CHECK(obj_read(path, NULL, NULL, &sink, &m, &err) == 0, "%s", err.msg);
    const char *names[] = {"Hard Shiny Plastic White", "Material #25", "Hard Shiny", ""};
    const float kd[] = {0.1f, 0.5f, 1.0f, 0.0f};
    for (uint32_t t = 0; t < m.n_tri && t < 4; t++) {
        const mesh_material *mt = &m.mats[m.tri_mat[t]];
        CHECK(!strcmp(mt->name, names[t]) && mt->defined && mt->kd.x == kd[t], "face %u: material \"%s\" (%s)", t,
              mt->name, mt->defined ? "defined" : "undefined");
    }
    CHECK(m.n_tri == 4 && m.n_mats == 5 && w.n == 0, "four faces, four materials and the default: %u %u, %d warnings",
          m.n_tri, m.n_mats, w.n);
    mesh_data_free(&m);
    const char *files[] = {"s.mtl", "s.obj"};
    for (int i = 0; i < 2; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, files[i]);
        unlink(path);
    }
    rmdir(dir);
}

int main(void)
{
    test_basic();
    test_corners();
    test_polygons();
    test_groups_materials();
    test_mtl_errors();
    test_errors();
    test_material_names();
    return check_done();
}
