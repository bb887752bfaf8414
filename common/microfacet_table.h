/** @file microfacet_table.h
 * The grids of the compiled albedo tables that energy compensation
 * and the principled material's layering read (microfacet_table.c, written
 * by tests/gen/genmftab.c; regenerate it with
 * `bin/gen/genmftab > common/microfacet_table.c`).
 *
 * Entries are fractions of 65535, looked up with linear interpolation in
 * each dimension.  Cosines are indexed by sqrt(mu) in equal steps, nodes
 * mu_i = (i / (N - 1))^2, dense at grazing angles where albedos change
 * fastest (the entry at mu = 0 is the albedo at MF_TAB_MU0, its limit);
 * roughness (alpha = roughness^2)
 * from 0 to 1 in equal steps; a dielectric's relative index eta >= 1 is
 * indexed by x = (eta - 1) / (eta + 1) in equal steps over [0, 0.5] (eta
 * from 1 to 3), and a boundary seen from the denser side (eta < 1) by x of
 * 1/eta. */
#ifndef FRANJA_MICROFACET_TABLE_H
#define FRANJA_MICROFACET_TABLE_H

#include <stdint.h>

#define MF_TAB_MU 32   /**< reflector tables: cosines */
#define MF_TAB_R 32    /**< reflector tables: roughness steps */
#define MF_TAB_DMU 16  /**< dielectric table: cosines */
#define MF_TAB_DR 16   /**< dielectric table: roughness steps */
#define MF_TAB_DETA 16 /**< dielectric table: index steps */
#define MF_TAB_MU0 1e-4 /**< the cosine the mu = 0 entries are integrated at */

/** E(mu) of a GGX reflector with F = 1: [masking][roughness][mu]. */
extern const uint16_t mf_tab_e[2][MF_TAB_R][MF_TAB_MU];
/** The same under the Fresnel factor (1 - wo.h)^5. */
extern const uint16_t mf_tab_e5[2][MF_TAB_R][MF_TAB_MU];
/** 2 int_0^1 E(mu) mu dmu of the interpolated rows above: [masking][roughness]. */
extern const uint16_t mf_tab_eavg[2][MF_TAB_R];
extern const uint16_t mf_tab_e5avg[2][MF_TAB_R];
/** Reflection plus transmission (flux) of a rough dielectric boundary with
 *  micro-facet Fresnel: [masking][0 entering, 1 leaving][eta][roughness][mu]. */
extern const uint16_t mf_tab_ed[2][2][MF_TAB_DETA][MF_TAB_DR][MF_TAB_DMU];

#endif
