/* test_appear_json.c -- the scene reader's errors on bad textures, maps, media
 * and lens.
 *
 * The appearance part of the scene format refuses bad input with the JSON
 * path and what was expected: textures, textured colours, bump and normal
 * maps, media, interfaces, the f-number lens and tone mapping. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "compile/json_scene.h"

static char dir[64];

/* A hook that decodes every file as a 2x2 RGB image. */
static int fake_image(const char *path, const void *data, size_t len, scene_image *img, fr_error *err)
{
    (void)data;
    (void)len;
    (void)path;
    (void)err;
    img->width = img->height = 2;
    img->channels = 3;
    img->pixels = calloc(12, sizeof(float));
    return 0;
}
static const scene_hooks hooks = {.texture = fake_image};

/* Parse a scene made of the fixed parts plus `extra` top-level members and
 * material `mat`; return the error message ("" on success). */
static const char *parse(const char *extra, const char *mat, const char *camera_extra, const scene_hooks *h)
{
    static fr_error err;
    char json[4096], file[128];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 4, \"height\": 4},"
             " \"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"fov\": 40%s},"
             " %s%s \"materials\": {\"m\": %s, \"lamp\": {\"type\": \"emitter\", \"emission\": [1, 1, 1]}},"
             " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"m\"},"
             "   {\"type\": \"sphere\", \"center\": [0, 3, 0], \"radius\": 0.5, \"material\": \"lamp\"}]}",
             camera_extra, extra, extra[0] ? "," : "", mat);
    snprintf(file, sizeof file, "%s/scene.json", dir);
    fr_builder b;
    bld_init(&b);
    int rc = json_scene_parse(json, file, h, &b, &err);
    bld_free(&b);
    return rc == 0 ? "" : err.msg;
}

#define LAMBERT "{\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}"
#define TEX "\"textures\": {\"wood\": {\"type\": \"image\", \"file\": \"wood.png\"}}"

/* Expect an error containing every string in `parts` (NULL-terminated). */
static void refused(const char *what, const char *msg, const char *const *parts)
{
    if (!msg[0]) {
        CHECK(0, "%s: accepted", what);
        return;
    }
    for (int i = 0; parts[i]; i++)
        CHECK(strstr(msg, parts[i]) != NULL, "%s: message '%s' lacks '%s'", what, msg, parts[i]);
}
#define REFUSED(what, msg, ...) refused(what, msg, (const char *const[]){__VA_ARGS__, NULL})

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/franja-appear-%ld", (long)getpid());
    char cmd[200];
    snprintf(cmd, sizeof cmd, "mkdir -p %s && touch %s/wood.png %s/sky.exr %s/anim.gif", dir, dir, dir, dir);
    if (system(cmd) != 0)
        return 1;

    /* What is accepted. */
    CHECK(!parse(TEX, "{\"type\": \"lambert\", \"albedo\": \"wood\"}", "", &hooks)[0], "bare texture colour: %s",
          parse(TEX, "{\"type\": \"lambert\", \"albedo\": \"wood\"}", "", &hooks));
    const char *ok = parse(TEX ", \"media\": {\"fog\": {\"sigma_a\": 0.1, \"sigma_s\": [0.1, 0.2, 0.3], \"g\": 0.4}},"
                           " \"medium\": \"fog\", \"tonemap\": {\"exposure\": 1.5, \"curve\": \"filmic\"}",
                           "{\"type\": \"phong\", \"diffuse\": {\"texture\": \"wood\", \"factor\": [0.5, 0.4, 0.3]},"
                           " \"glossy\": [0.2, 0.2, 0.2], \"exponent\": 30, \"bump\": {\"texture\": \"wood\", \"strength\": 0.1},"
                           " \"normal_map\": \"wood\"}",
                           ", \"fstop\": 4, \"focal_length\": 0.05", &hooks);
    CHECK(!ok[0], "a full appearance scene is refused: %s", ok);

    /* Textures. */
    REFUSED("missing file", parse("\"textures\": {\"t\": {\"type\": \"image\", \"file\": \"nope.png\"}}", LAMBERT, "", &hooks),
            "textures.t.file", "nope.png", "No such file");
    REFUSED("unsupported format", parse("\"textures\": {\"t\": {\"type\": \"image\", \"file\": \"anim.gif\"}}", LAMBERT, "", &hooks),
            "textures.t.file", "unsupported image format", "png");
    REFUSED("no file", parse("\"textures\": {\"t\": {\"type\": \"image\"}}", LAMBERT, "", &hooks), "textures.t.file", "missing");
    REFUSED("bad type", parse("\"textures\": {\"t\": {\"type\": \"noise\"}}", LAMBERT, "", &hooks), "textures.t.type",
            "image or checker");
    REFUSED("bad wrap", parse("\"textures\": {\"t\": {\"type\": \"image\", \"file\": \"wood.png\", \"wrap\": \"mirror\"}}",
                              LAMBERT, "", &hooks), "textures.t.wrap", "repeat or clamp");
    REFUSED("bad colorspace", parse("\"textures\": {\"t\": {\"type\": \"image\", \"file\": \"wood.png\", \"colorspace\": \"rgb\"}}",
                                    LAMBERT, "", &hooks), "textures.t.colorspace", "srgb");
    REFUSED("bad scale", parse("\"textures\": {\"t\": {\"type\": \"checker\", \"colors\": [[1,1,1],[0,0,0]], \"scale\": [1]}}",
                               LAMBERT, "", &hooks), "textures.t.scale", "[u, v]");
    REFUSED("checker colours", parse("\"textures\": {\"t\": {\"type\": \"checker\", \"colors\": [[1,1,1],[0,-1,0]]}}",
                                     LAMBERT, "", &hooks), "textures.t.colors[1][1]", ">= 0");
    REFUSED("unknown texture field", parse("\"textures\": {\"t\": {\"type\": \"image\", \"file\": \"wood.png\", \"gamma\": 2}}",
                                           LAMBERT, "", &hooks), "textures.t.gamma", "unknown field");
    REFUSED("unknown texture name", parse(TEX, "{\"type\": \"lambert\", \"albedo\": \"oak\"}", "", &hooks),
            "materials.m.albedo", "no texture named 'oak'");
    REFUSED("texture object without name", parse(TEX, "{\"type\": \"lambert\", \"albedo\": {\"factor\": [1, 1, 1]}}", "", &hooks),
            "materials.m.albedo.texture", "missing");
    REFUSED("image without compiler", parse(TEX, "{\"type\": \"lambert\", \"albedo\": \"wood\"}", "", NULL),
            "textures.wood", "franja compile");
    REFUSED("normal map from a grey checker is fine but strength < 0",
            parse(TEX, "{\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5], \"normal_map\": {\"texture\": \"wood\", \"strength\": -1}}",
                  "", &hooks), "materials.m.normal_map.strength", ">= 0");
    REFUSED("bump not a texture", parse(TEX, "{\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5], \"bump\": 3}", "", &hooks),
            "materials.m.bump", "texture name");

    /* Media. */
    REFUSED("negative sigma_a", parse("\"media\": {\"fog\": {\"sigma_a\": -0.1, \"sigma_s\": 1}}", LAMBERT, "", &hooks),
            "media.fog.sigma_a", ">= 0");
    REFUSED("negative sigma_s channel", parse("\"media\": {\"fog\": {\"sigma_s\": [1, -2, 1]}}", LAMBERT, "", &hooks),
            "media.fog.sigma_s", ">= 0");
    REFUSED("empty medium", parse("\"media\": {\"fog\": {\"g\": 0.2}}", LAMBERT, "", &hooks), "media.fog", "both zero");
    REFUSED("g out of range", parse("\"media\": {\"fog\": {\"sigma_s\": 1, \"g\": 1}}", LAMBERT, "", &hooks), "media.fog.g",
            "[-0.99, 0.99]");
    REFUSED("sigma not a number", parse("\"media\": {\"fog\": {\"sigma_s\": \"thick\"}}", LAMBERT, "", &hooks),
            "media.fog.sigma_s", "number or [r, g, b]");
    REFUSED("unknown fog", parse("\"medium\": \"smoke\"", LAMBERT, "", &hooks), "medium", "no medium named 'smoke'");
    REFUSED("unknown interior", parse("", "{\"type\": \"interface\", \"medium\": \"smoke\"}", "", &hooks),
            "materials.m.medium", "no medium named 'smoke'");
    REFUSED("interface without medium", parse("", "{\"type\": \"interface\"}", "", &hooks), "materials.m.medium",
            "interface");
    REFUSED("emitting interface", parse("\"media\": {\"fog\": {\"sigma_s\": 1}}",
                                        "{\"type\": \"interface\", \"medium\": \"fog\", \"emission\": [1, 1, 1]}", "", &hooks),
            "materials.m", "invisible");

    /* Camera lens and tone mapping. */
    REFUSED("fstop alone", parse("", LAMBERT, ", \"fstop\": 2", &hooks), "camera.focal_length", "both");
    REFUSED("fstop and aperture", parse("", LAMBERT, ", \"fstop\": 2, \"focal_length\": 0.05, \"aperture\": 0.1", &hooks),
            "camera.aperture", "not both");
    REFUSED("negative fstop", parse("", LAMBERT, ", \"fstop\": -2, \"focal_length\": 0.05", &hooks), "camera.fstop", "> 0");
    REFUSED("bad curve", parse("\"tonemap\": {\"curve\": \"aces\"}", LAMBERT, "", &hooks), "tonemap.curve", "none or filmic");
    REFUSED("bad exposure", parse("\"tonemap\": {\"exposure\": 100}", LAMBERT, "", &hooks), "tonemap.exposure", "[-64, 64]");

    /* The box shape. */
    fr_builder b;
    fr_error err;
    bld_init(&b);
    int rc = json_scene_parse("{\"image\": {\"width\": 4, \"height\": 4},"
                            " \"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"fov\": 40},"
                            " \"materials\": {\"lamp\": {\"type\": \"emitter\", \"emission\": [1, 1, 1]}},"
                            " \"shapes\": [{\"type\": \"box\", \"min\": [0, 0, 0], \"max\": [1, -1, 1], \"material\": \"lamp\"}]}",
                            "box.json", &hooks, &b, &err);
    bld_free(&b);
    REFUSED("box max below min", rc == 0 ? "" : err.msg, "shapes[0].max", "greater than min");

    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        printf("note: could not remove %s\n", dir);
    return check_done();
}
