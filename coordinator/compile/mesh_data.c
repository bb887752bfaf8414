/* mesh_data.c -- the importers' mesh: freeing it, its materials as
 * Franja materials (see mesh_data.h). */
#include "compile/mesh_data.h"

#include <stdlib.h>
#include <string.h>

#include "bsdf.h"
#include "compile/builder.h"

void mesh_data_free(mesh_data *m)
{
    free(m->pos); free(m->nrm); free(m->uv);
    free(m->tri); free(m->tri_flags); free(m->tri_mat);
    free(m->mats);
    memset(m, 0, sizeof *m);
}

void mesh_data_material(const mesh_material *src, fr_material *m)
{
    bld_material_init(m);
    m->diffuse = src->kd;
    int il = src->illum;
    if (il == 4 || il == 6 || il == 7 || il == 9) {
        m->transmit = src->tf;
        if (src->ni >= 1.0f / 16.0f && src->ni <= 16.0f && src->ni != 1.0f)
            m->ior = src->ni;
    } else if (il == 3 || il == 5) {
        m->specular = src->ks;
    } else if (il != 0 && il != 1 && !v3_is_zero(src->ks)) {
        m->glossy = src->ks;
        m->exponent = src->ns;
    }
    m->emission = src->ke;
    /* Files often give Kd + Ks > 1: scale the lobes down together so the
     * material never reflects more than it receives. */
    vec3 sum = v3_add(v3_add(m->diffuse, m->glossy), v3_add(m->specular, m->transmit));
    float mx = v3_max(sum);
    if (mx > 1.0f) {
        float k = 1.0f / mx;
        m->diffuse = v3_scale(m->diffuse, k);
        m->glossy = v3_scale(m->glossy, k);
        m->specular = v3_scale(m->specular, k);
        m->transmit = v3_scale(m->transmit, k);
    }
    bsdf_lobe_probs(m);
}
