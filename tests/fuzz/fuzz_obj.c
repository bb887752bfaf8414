/* fuzz_obj.c -- libFuzzer target for the OBJ and MTL readers
 * (coordinator/obj.h).  An input whose first byte is 'M' is
 * read as MTL, any other as OBJ (mtllib statements are skipped: no files
 * are opened). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "obj.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    obj_mesh m;
    fr_error err;
    if (size > 0 && data[0] == 'M') {
        memset(&m, 0, sizeof m);
        if (obj_parse_mtl((const char *)data + 1, size - 1, "fuzz.mtl", &m, &err) == 0)
            for (uint32_t i = 0; i < m.n_mats; i++) {
                fr_material fm;
                obj_material_convert(&m.mats[i], &fm);
            }
        obj_free(&m);
    } else if (obj_parse((const char *)data, size, "fuzz.obj", NULL, &m, &err) == 0) {
        obj_free(&m);
    }
    return 0;
}
