/* fuzz_gltf.c -- libFuzzer target for the glTF reader: any bytes as a .gltf
 * or .glb document (external URIs refused, images not decoded), imported as
 * a whole scene with at most 2^16 triangles and, when that succeeds,
 * frozen (BVH build, serialization and the loader's checks); then imported
 * again posed by its animations at a frame (from the input's length) with
 * a shutter of half a frame (gltf_anim.h: samplers, morph weights, skins,
 * the camera at the shutter's ends). */
#include <stdint.h>
#include <stdlib.h>

#include "compile/freeze.h"
#include "compile/gltf_scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fr_builder b;
    fr_error err;
    bld_init(&b);
    if (gltf_build_scene("fuzz.gltf", data, size, NULL, NULL, 1u << 16, &b, &err) == 0) {
        fr_scene s;
        if (frz_scene(&b, &s, &err) == 0)
            scn_free(&s);
    }
    bld_free(&b);
    scene_hooks timed = {0};
    timed.timed = 1;
    timed.frame = (double)(size % 61);
    timed.fps = 24.0;
    timed.shutter = 0.5;
    bld_init(&b);
    if (gltf_build_scene("fuzz.gltf", data, size, &timed, NULL, 1u << 16, &b, &err) == 0) {
        fr_scene s;
        if (frz_scene(&b, &s, &err) == 0)
            scn_free(&s);
    }
    bld_free(&b);
    return 0;
}
