/** @file scene.h
 * The scene as the renderer sees it.
 *
 * A scene is a set of flat arrays of plain structs.  The same bytes are the
 * sections of the binary scene file (see fbin.h and docs in
 * common/FORMAT.md): a worker maps the file and points these arrays into
 * it, with no per-element parsing.  So every struct here is fixed-size,
 * made of 4-byte fields, and little-endian on disk.
 *
 * Units are the scene's own (the Cornell box is in millimetres); radiance is
 * linear RGB; angles in the scene file are degrees, radians here.
 *
 * Ownership: an fr_scene owns `blob` (malloc'd or mmap'd, per `mapped`);
 * every array points into it, except nodes and leaves once copied to
 * `bvh_copy` (scene_pages.h), which it also owns.  scn_free() releases
 * both.
 */
#ifndef FRANJA_SCENE_H
#define FRANJA_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "vec.h"

#define FR_NONE 0xffffffffu /**< "no index" for optional uint32 references */

/** How a scene is rendered by default (franja-worker --integrator
 * overrides it): unidirectional path tracing, bidirectional path tracing
 * (bdpt.h), or Metropolis light transport (mlt_path.h). */
enum { FR_INTEGRATOR_PATH = 0, FR_INTEGRATOR_BDPT = 1, FR_INTEGRATOR_MLT = 2, FR_INTEGRATORS };

/** Whether integrator i's partial images carry fixed-point splats over the
 * whole image (splat.h): bidirectional and Metropolis renders. */
static inline int fr_integrator_splats(uint32_t i) { return i == FR_INTEGRATOR_BDPT || i == FR_INTEGRATOR_MLT; }

/** Image and sampling settings. */
typedef struct {
    uint32_t width, height;    /**< pixels */
    uint32_t spp;              /**< samples per pixel */
    uint32_t max_depth;        /**< bounces; a path has at most max_depth+1 vertices after the camera */
    uint32_t seed;             /**< decorrelates renders of the same scene */
    uint32_t integrator;       /**< FR_INTEGRATOR_* */
    float noise_threshold;     /**< adaptive sampling: a pixel stops once the estimated relative standard error of
                                    its mean luminance is below this (pathtrace.h); 0 = off, every pixel takes spp */
    uint32_t passes;           /**< render passes `franja render` asks for by default (passes.h bits); 0 = none */
} fr_settings;

/** A pinhole or thin-lens camera. */
typedef struct {
    vec3 position, target, up;
    float vfov;                /**< vertical field of view, radians */
    float aperture;            /**< lens radius, scene units; 0 = pinhole */
    float focus;               /**< focus distance along the view axis */
    vec3 forward, right, upv;  /**< derived (bld_camera_finish): orthonormal; right = image +x, upv = image -y */
    float tan_half;            /**< derived (bld_camera_finish): tan(vfov/2) */
    float pad;
} fr_camera;

/** Material models (fr_material.model). */
enum {
    FR_MAT_LOBES = 0,      /**< the weighted lobes below */
    FR_MAT_CONDUCTOR = 1,  /**< rough conductor: reflectance in `specular` (and tex_specular) */
    FR_MAT_DIELECTRIC = 2, /**< rough dielectric boundary: tint in `transmit` (and tex_transmit), index `ior` */
    FR_MAT_PRINCIPLED = 3, /**< glTF metallic-roughness: base colour in `diffuse` (and tex_diffuse), `ior` */
    FR_MAT_MODELS
};

/** How a conductor's reflectance depends on the angle (fr_material.fresnel;
 * the MF_FRESNEL_* of microfacet.h). */
enum {
    FR_FRESNEL_SCHLICK = 0, /**< `specular` is F0 of Schlick's approximation */
    FR_FRESNEL_EXACT = 1,   /**< exact Fresnel of the complex index eta + i k, tinted by `specular` */
    FR_FRESNEL_NONE = 2,    /**< `specular` at every angle */
    FR_FRESNEL_MODES
};

/** Options of the microfacet models (bits of fr_material.mf_flags). */
enum {
    FR_MF_SEPARABLE = 1,     /**< separable Smith masking (as Cycles 3.4) instead of height-correlated */
    FR_MF_COMPENSATE = 2,    /**< multiple-scattering energy compensation */
    FR_MF_MACRO_FRESNEL = 4, /**< dielectric: Fresnel once with the shading normal (Cycles 3.4's Glass) */
    FR_MF_GLTF_COUPLING = 8, /**< principled: glTF's fresnel_mix as written instead of albedo coupling */
    FR_MF_CYCLES_COUPLING = 16, /**< principled: Cycles 3.4's Principled BSDF (Disney diffuse added) */
    FR_MF_ALL = 31
};

/** A material is a weighted set of lobes (model FR_MAT_LOBES), one of
 * which is picked per scattering event by Russian roulette with probability
 * proportional to its weight, or a microfacet model (microfacet.h).  A
 * plain Lambert material has only `diffuse`; a Phong material `diffuse` and
 * `glossy`; a mirror `specular`; smooth glass `transmit`.  Lobe colours are
 * the albedos the lobe contributes: energy is conserved when the
 * per-channel sum of the four is at most 1.  The microfacet models keep
 * their colour in one of the four (see FR_MAT_*) and leave the others 0. */
typedef struct {
    vec3 diffuse;              /**< Lambert albedo */
    vec3 glossy;               /**< normalized Phong albedo */
    vec3 specular;             /**< perfect mirror reflectance */
    vec3 transmit;             /**< smooth dielectric tint (Fresnel picks reflect/refract) */
    vec3 emission;             /**< emitted radiance, front side only (unless two_sided) */
    float exponent;            /**< Phong exponent, >= 0 */
    float ior;                 /**< dielectric index of refraction (inside / outside) */
    float p_lobe[4];           /**< cumulative lobe-selection probabilities: diffuse, glossy, specular, transmit */
    uint32_t two_sided;        /**< emission on both sides */
    /** Textures (indices into textures, or FR_NONE).  A textured colour is
     * the colour above times the texture's value at the hit's UV, so the
     * colour above is a tint (white when the scene file gives a bare
     * texture); reflectance textures are clamped to [0, 1] when looked up,
     * which keeps the energy bound checked on the tints. */
    uint32_t tex_diffuse;
    uint32_t tex_bump;         /**< grey height map: displacement = bump_strength * value, scene units */
    float bump_strength;
    uint32_t tex_glossy, tex_specular, tex_transmit, tex_emission;
    uint32_t tex_normal;       /**< tangent-space normal map (linear RGB, 0.5 = 0) */
    float normal_strength;     /**< scales the map's tangential components */
    uint32_t medium;           /**< medium inside the shape: 1 + index into media, 0 = none */
    uint32_t interface;        /**< 1: no surface at all, only a boundary between media */
    uint32_t model;            /**< FR_MAT_* */
    uint32_t mf_flags;         /**< microfacet models: FR_MF_* bits */
    uint32_t fresnel;          /**< conductor: FR_FRESNEL_* */
    float roughness;           /**< microfacet models: [0, 1], alpha = roughness^2 */
    float anisotropy;          /**< microfacet models: [-1, 1], 0 isotropic, > 0 rougher along dpdu */
    float metallic;            /**< principled: [0, 1] */
    float transmission;        /**< principled: [0, 1], the share of the dielectric that refracts */
    vec3 eta, k;               /**< conductor, FR_FRESNEL_EXACT: complex index of refraction per channel */
    vec3 fresnel_avg;          /**< derived (bsdf_material_finish): the exact conductor's cosine-weighted
                                    average Fresnel factor, untinted */
    uint32_t tex_roughness;    /**< times roughness: a grey texture, or the G channel of an RGB one (glTF) */
    uint32_t tex_metallic;     /**< times metallic: a grey texture, or the B channel of an RGB one (glTF) */
    uint32_t tex_transmission; /**< times transmission: a grey texture, or the R channel of an RGB one (glTF) */
} fr_material;

/** A texture: an image stored in the scene at its own precision, with its
 * mip-maps, or a procedural checkerboard.  Lookups map the surface's UV
 * through uv * scale + offset; v grows upward, so v = 0 is the image's
 * bottom row (the OBJ convention).
 *
 * An image's texels live in `texels` (32-bit words): mip level k has
 * max(1, width >> k) x max(1, height >> k) texels, rows from the top, each
 * texel `channels` values in `format`, the level starting at word
 * first[k] (so every level is 4-byte aligned; its last word is padded with
 * zero bytes).  Level k's texel (x, y) is the mean, in linear values, of
 * the texels (2x..2x+1, 2y..2y+1) of level k - 1, the last column (row)
 * also taking the odd one left over, rounded to the nearest value of the
 * format (mip.h: mip_encode). */
enum { FR_TEX_IMAGE = 0, FR_TEX_CHECKER = 1 };
/** The largest image width or height a texture may have, in pixels. */
#define FR_TEX_MAX_SIDE 65536u
/** Mip levels of an image of FR_TEX_MAX_SIDE: log2(65536) + 1. */
#define FR_TEX_MAX_LEVELS 17u
enum { FR_WRAP_REPEAT = 0, FR_WRAP_CLAMP = 1 };
enum { FR_FILTER_BILINEAR = 0, FR_FILTER_NEAREST = 1 };
/** How an image's values are stored (each value of each channel):
 * F32 a linear binary32; U8_SRGB a byte holding the sRGB-encoded value
 * k / 255 (decoded through a 256-entry table); U8 a byte k meaning k / 255;
 * U16 a 16-bit k meaning k / 65535; U16_SRGB a 16-bit sRGB-encoded
 * k / 65535; F16 an IEEE 754 binary16 (half), linear. */
enum {
    FR_TEXEL_F32 = 0, FR_TEXEL_U8_SRGB = 1, FR_TEXEL_U8 = 2, FR_TEXEL_U16 = 3, FR_TEXEL_U16_SRGB = 4,
    FR_TEXEL_F16 = 5, FR_TEXEL_FORMATS = 6
};
typedef struct {
    uint32_t kind;             /**< FR_TEX_* */
    uint32_t width, height;    /**< image: pixels of level 0 */
    uint32_t channels;         /**< image: 1 (grey) or 3 (RGB) values per texel */
    uint32_t format;           /**< image: FR_TEXEL_* */
    uint32_t levels;           /**< image: mip levels stored, 1 .. the full chain down to 1 x 1 */
    uint32_t wrap;             /**< FR_WRAP_* */
    uint32_t filter;           /**< FR_FILTER_* */
    vec2 scale, offset;        /**< UV transform */
    vec3 color0, color1;       /**< checker: the square at the UV origin, the other one */
    uint32_t first[FR_TEX_MAX_LEVELS]; /**< image: word index into texels of each level; 0 past `levels` */
    uint32_t pad;
} fr_texture;

/** A homogeneous participating medium: coefficients per colour channel in
 * inverse scene units, Henyey-Greenstein phase function (g = 0 is
 * isotropic; g > 0 scatters forward). */
typedef struct {
    vec3 sigma_a, sigma_s;
    float g;
    uint32_t pad;
} fr_medium;

/** Which medium fills space outside every shape with an interior medium
 * (fog), and which one the camera sits in: 1 + index into media, 0 = none.
 * Shapes with interior media must be closed, outward-facing and must not
 * overlap or nest. */
typedef struct {
    uint32_t fog;
    uint32_t camera_medium;
    uint32_t pad[2];
} fr_volume;

/** Tone mapping defaults for the final image (the coordinator applies them
 * once, after stitching; the linear radiance in partial images and HDR
 * outputs is never tone-mapped). */
enum { FR_CURVE_NONE = 0, FR_CURVE_FILMIC = 1 };
typedef struct {
    float exposure;            /**< stops: LDR values are scaled by 2^exposure */
    uint32_t curve;            /**< FR_CURVE_* */
    uint32_t pad[2];
} fr_tonemap;

enum { FR_PRIM_TRIANGLE = 0, FR_PRIM_SPHERE = 1, FR_PRIM_RECT = 2, FR_PRIM_INSTANCE = 3, FR_PRIM_KINDS };

/** One entry per bounded primitive; the BVH's leaves hold ranges of this
 * array.  `index` points into the array of the primitive's kind.  An
 * FR_PRIM_INSTANCE (only in the top-level BVH) places a mesh: its triangles
 * are the prims of that fr_mesh, at the end of the array, and its material
 * and light are unused (0 and FR_NONE). */
typedef struct {
    uint32_t kind;             /**< FR_PRIM_* */
    uint32_t index;            /**< into spheres, rects, triangles or instances */
    uint32_t material;
    uint32_t light;            /**< index into lights if emissive, else FR_NONE */
} fr_prim;

/** A sphere (its front side faces out). */
typedef struct { vec3 center; float radius; } fr_sphere;

/** Parallelogram origin + s*edge_u + t*edge_v, s,t in [0,1]; its front side
 * faces cross(edge_u, edge_v). */
typedef struct {
    vec3 origin, edge_u, edge_v;
    /** Derived by geo_rect_make, so a ray test costs two dot products:
     * normal = edge_u x edge_v (not unit), and the dual basis, with
     * (p - origin) . dual_u = s and (p - origin) . dual_v = t in the plane. */
    vec3 normal, dual_u, dual_v;
} fr_rect;

/** Vertex indices into positions (and normals/uvs when the mesh has them;
 * one index per vertex for all three).  The front side faces
 * cross(p1-p0, p2-p0). */
typedef struct { uint32_t v[3]; uint32_t flags; } fr_triangle;
enum { FR_TRI_NORMALS = 1, FR_TRI_UVS = 2 };

/** Infinite plane through `point` facing `normal` (unit).  Never a light. */
typedef struct { vec3 point, normal; uint32_t material; uint32_t pad; } fr_plane;

/** A light.  Kinds:
 *  - FR_LIGHT_POINT: light from `position`, `intensity` W/sr in every direction;
 *  - FR_LIGHT_PRIM: an emissive primitive (area light), `prim` and its `area`;
 *  - FR_LIGHT_SPOT: a point light shining along unit `axis`, `intensity`
 *    W/sr on the axis, scaled by glTF's smooth falloff between the cosines
 *    `cone_cos` (outer cone) and `cone_aux` (inner cone), lgt_spot_falloff;
 *  - FR_LIGHT_SUN: a distant light in direction `axis` (unit, from the scene
 *    toward the sun); `intensity` is the irradiance (W/m^2) of a surface
 *    facing it; a disk of half-angle acos(cone_cos), cone_aux = 1 - cone_cos
 *    (kept exact for small angles); both 1 and 0 for a delta sun;
 *  - FR_LIGHT_ENV: the environment; its parameters are in fr_world.
 * Distant lights (sun, environment) come first in the table, so escaping
 * rays test only them.  The pick probabilities follow the lights' power:
 * the table that paths starting on a light (bidirectional methods) and
 * equiangular sampling in media use, where no point of the scene is known;
 * next-event estimation from a point uses the light tree (fr_light_node)
 * for the local lights and these picks for the distant ones. */
enum { FR_LIGHT_POINT = 0, FR_LIGHT_PRIM = 1, FR_LIGHT_SPOT = 2, FR_LIGHT_SUN = 3, FR_LIGHT_ENV = 4, FR_LIGHT_KINDS };
typedef struct {
    uint32_t kind;             /**< FR_LIGHT_* */
    uint32_t prim;             /**< FR_LIGHT_PRIM: index into prims; FR_NONE for the other kinds */
    vec3 position;             /**< FR_LIGHT_POINT, FR_LIGHT_SPOT */
    vec3 intensity;            /**< POINT, SPOT: W/sr (radiance x area units); SUN: irradiance normal to axis */
    vec3 axis;                 /**< SPOT: unit direction it shines along; SUN: unit direction toward the sun */
    float area;                /**< FR_LIGHT_PRIM: surface area */
    float cone_cos;            /**< SPOT: cosine of the outer cone angle; SUN: cosine of the disk's half-angle */
    float cone_aux;            /**< SPOT: cosine of the inner cone angle; SUN: 1 - cone_cos */
    float pick;                /**< power table: probability of picking this light (sums to 1) */
    float cdf;                 /**< sum of pick over lights[0..this], for binary search */
} fr_light;

/** A node of the light tree (Conty Estevez & Kulla 2018): a binary tree
 * over the local lights (every light but the sun and the environment) that
 * bounds, for the lights under it, their points (box lo..hi), the normals
 * they emit around (the cone of unit `axis` with cosine of its half-angle
 * `cos_o`; -1: every direction), how far beyond those normals they emit
 * (`cos_e`: the cosine of that spread, 0 for a hemisphere) and their total
 * power.  Light nd + j (nd: the number of distant lights) is leaf node j;
 * inner nodes follow the leaves, each after its two children, and the
 * root is the last node.  light.c walks it to pick a light by an importance
 * that each point of the scene gives each node. */
enum { FR_LNODE_TWO_SIDED = 1 };
typedef struct {
    vec3 lo, hi;               /**< bounds of the lights' points */
    vec3 axis;                 /**< unit axis of the normals' cone */
    float cos_o;               /**< cosine of the normals' cone half-angle, in [-1, 1] */
    float cos_e;               /**< cosine of the emission's spread about any of those normals, in [-1, 1] */
    float power;               /**< the lights' power (the power table's estimate), >= 0 */
    uint32_t child[2];         /**< inner node: its children (below its own index); leaf: FR_NONE */
    uint32_t parent;           /**< FR_NONE for the root, else above its own index */
    uint32_t flags;            /**< FR_LNODE_TWO_SIDED: the lights emit about -axis too */
} fr_light_node;

/** What surrounds the scene: its bounding sphere (distant lights enter
 * through it) and the environment light.  The environment is a constant
 * radiance `env_color`, or an equirectangular map (texture `env_texture`,
 * an image) times env_color.  A direction d (unit, away from the scene) is
 * first turned about +y: d' = (c x + s z, y, -s x + c z), c = rot_cos,
 * s = rot_sin; then u = 1/2 + atan2(d'.z, d'.x) / (2 pi) and
 * v = 1 - acos(d'.y) / pi pick the texel (v = 1 is the image's top row),
 * which is Cycles' mapping for the same scene in Blender's +z-up frame.
 *
 * The map is importance-sampled from tables in `distrib`, starting at
 * dist_first, for a map of w x h texels: pdf[h*w] (piecewise-constant
 * density over the unit square (u, 1 - v), row 0 at the top, integrating
 * to 1), then marginal[h+1] (cumulative over rows, from 0 to 1), then
 * conditional[h][w+1] (cumulative over each row's columns, 0 to 1). */
enum { FR_ENV_NONE = 0, FR_ENV_CONSTANT = 1, FR_ENV_MAP = 2 };
typedef struct {
    vec3 center;               /**< bounding sphere of the bounded shapes and the planes' points */
    float radius;              /**< > 0 */
    uint32_t env;              /**< FR_ENV_* */
    uint32_t env_light;        /**< index of the FR_LIGHT_ENV light, FR_NONE without an environment */
    uint32_t env_texture;      /**< FR_ENV_MAP: index into textures */
    uint32_t dist_first;       /**< FR_ENV_MAP: index of the tables in distrib */
    vec3 env_color;            /**< radiance (constant), or the map's multiplier (colour x strength) */
    float rot_cos, rot_sin;    /**< the turn about +y */
    uint32_t pad[3];
} fr_world;

/** An 8-wide BVH node (256 bytes, four cache lines): the boxes of its
 * eight children side by side (structure of arrays), so one ray is tested
 * against all of them with a few vector operations per plane.  box[0..2]
 * are the lower x, y, z bounds, box[3..5] the upper ones, one lane per
 * child.
 *
 * Child slot i is
 *   - an inner node:  leaf[i] == 0, child[i] = index into nodes (> this node);
 *   - a leaf:         leaf[i] = number of leaf blocks (1..FR_BVH_LEAF_MAX),
 *                     plus FR_BVH_MIXED if some lane is not a triangle,
 *                     child[i] = index of the first block in leaves;
 *   - empty:          child[i] = FR_NONE, leaf[i] = 0, box lower = +inf,
 *                     upper = -inf (a box no ray enters).
 * Node 0 is the root; every other node is the child of exactly one node. */
#define FR_BVH_WIDTH 8
typedef struct {
    float box[6][FR_BVH_WIDTH];
    uint32_t child[FR_BVH_WIDTH];
    uint32_t leaf[FR_BVH_WIDTH];
} fr_bvh_node;

#define FR_BVH_LEAF_MAX 255u
#define FR_BVH_MIXED 0x100u
/** Deepest node (the root is at depth 1): a deeper tree is refused when a
 * scene is loaded, so traversal's stack has a fixed size. */
#define FR_BVH_MAX_DEPTH 64

/** A leaf block: up to four primitives with their triangle vertices copied
 * in leaf order (structure of arrays: v[3*k + axis][lane] is coordinate
 * `axis` of vertex k of lane `lane`), so traversal reads one contiguous
 * 160-byte block instead of following three indices per triangle.  prim[lane]
 * is the index into prims, FR_NONE for an unused lane; lanes that are not
 * triangles (spheres, rects; only in FR_BVH_MIXED leaves) have zero vertices
 * and are intersected through prims. */
typedef struct {
    float v[9][4];
    uint32_t prim[4];
} fr_bvh_leaf;

/** An instanced mesh: a BVH of its own (a bottom-level BVH, in object
 * space) over triangles that only instances place.  Its nodes and leaf
 * blocks are mesh_nodes[node_first ..] and mesh_leaves[leaf_first ..],
 * with child indices relative to those starts (node 0 of the range is its
 * root), its leaf lanes name prims[prim_first .. prim_first + n_prims),
 * all triangles and none of them a light.  Meshes follow one another in
 * every array: mesh 0 starts at node 0 and leaf 0, and its prims start
 * right after the prims of the top-level BVH. */
typedef struct {
    uint32_t node_first, n_nodes;
    uint32_t leaf_first, n_leaves;
    uint32_t prim_first, n_prims;
    uint32_t pad[2];
} fr_mesh;

/** A mesh placed in the world by an affine transform: a world point is
 * xf * (p, 1) for an object-space point p (xf row-major, 3 rows of 4),
 * and inv is the inverse transform.  A ray is taken into object space by
 * inv without renormalising its direction, so distances along it are the
 * world's; normals go out by the transpose of inv's linear part. */
typedef struct {
    float xf[3][4];
    float inv[3][4];
    uint32_t mesh;             /**< index into meshes */
    uint32_t motion;           /**< 0: still; else 1 + index into inst_motions (xf and inv are then the
                                    pose at shutter open, and the pose at the ray's time is used) */
    uint32_t pad[2];
} fr_instance;

/** How a moving instance moves across the shutter (FR_MOTION_INSTANCES):
 * its transform at shutter open and close, each split into a translation,
 * a rotation (unit quaternion x, y, z, w) and a stretch (a 3x3 matrix:
 * scale and shear, what the polar decomposition leaves after the
 * rotation), so that the object-to-world transform is
 * world = T + R S p.  At time u in [0, 1] (motion.h's motion_at): T and S
 * blend linearly, R along the shortest arc from q0 to q1 (slerp; q0 . q1
 * >= 0, at most half a turn).  The top-level BVH bounds the instance over
 * the whole shutter. */
typedef struct {
    vec3 t0, t1;               /**< translation at open, close */
    float q0[4], q1[4];        /**< rotation at open, close: unit quaternions (x, y, z, w), q0 . q1 >= 0 */
    float s0[3][3], s1[3][3];  /**< stretch at open, close (row-major) */
    float angle;               /**< the angle between q0 and q1 in 4-space, [0, pi/2] (half the turn) */
    float inv_sin;             /**< 1 / sin(angle); 0 below MOTION_SLERP_MIN, where the blend is linear (nlerp) */
    uint32_t pad[2];
} fr_inst_motion;

/** A material's name (material_names section): NUL-terminated UTF-8, at
 * most 63 bytes (longer names are cut), no control character; "" when
 * the scene file gave none. */
typedef struct {
    char name[64];
} fr_name;

/** Motion blur (fr_motion.flags). */
enum { FR_MOTION_CAMERA = 1, FR_MOTION_INSTANCES = 2 };

/** What moves while the shutter is open.  A camera sample has a time u in
 * [0, 1) across the shutter (from its sampler, pathtrace.h), 0 at
 * shutter open; with FR_MOTION_CAMERA the camera at u is `camera` (the
 * pose at shutter open) blended toward `camera_close` (camera.h's
 * cam_at); with FR_MOTION_INSTANCES some instances move (fr_inst_motion)
 * and every ray of the sample, camera, bounce and shadow rays alike,
 * carries u (fr_ray.time).  Without flags nothing moves and no sample
 * draws a time. */
typedef struct {
    uint32_t flags;            /**< FR_MOTION_* */
    float shutter;             /**< how long the shutter is open, seconds (informational; 0: no shutter) */
    uint32_t pad[2];
    fr_camera camera_close;    /**< the camera at shutter close (derived fields set), with FR_MOTION_CAMERA */
} fr_motion;

/** A whole scene: its settings and camera, and each section as an array
 * and its length (pointing into `blob`). */
typedef struct {
    fr_settings settings;
    fr_camera camera;

    const fr_material *materials; uint32_t n_materials;
    const fr_prim *prims;         uint32_t n_prims;
    const fr_sphere *spheres;     uint32_t n_spheres;
    const fr_rect *rects;         uint32_t n_rects;
    const fr_triangle *triangles; uint32_t n_triangles;
    const vec3 *positions;        uint32_t n_positions;
    const vec3 *normals;          uint32_t n_normals;
    const vec2 *uvs;              uint32_t n_uvs;
    const fr_texture *textures;   uint32_t n_textures;
    const uint32_t *texels;       uint32_t n_texels;   /**< 32-bit words (fr_texture) */
    const fr_medium *media;       uint32_t n_media;
    fr_volume volume;
    fr_tonemap tonemap;
    const fr_plane *planes;       uint32_t n_planes;
    const fr_light *lights;       uint32_t n_lights;
    const fr_bvh_node *nodes;     uint32_t n_nodes;
    const fr_bvh_leaf *leaves;    uint32_t n_leaves;
    fr_world world;
    const float *distrib;         uint32_t n_distrib;
    const fr_mesh *meshes;        uint32_t n_meshes;
    const fr_instance *instances; uint32_t n_instances;
    const fr_bvh_node *mesh_nodes; uint32_t n_mesh_nodes;
    const fr_bvh_leaf *mesh_leaves; uint32_t n_mesh_leaves;
    const fr_light_node *light_nodes; uint32_t n_light_nodes;
    const fr_name *material_names; uint32_t n_material_names; /**< 0, or one per material */
    fr_motion motion;
    /** 0, or the object of each prim, then of each plane, then of each
     * instance (an index into object_names; a prim of an instanced mesh
     * takes its instance's). */
    const uint32_t *objects; uint32_t n_objects;
    const fr_name *object_names; uint32_t n_object_names; /**< the objects' names */
    /** 0, or each light's group (an index into group_names; 0 is
     * "default"), for the light_groups pass. */
    const uint32_t *light_groups; uint32_t n_light_groups;
    const fr_name *group_names; uint32_t n_group_names; /**< the light groups' names */
    const fr_inst_motion *inst_motions; uint32_t n_inst_motions; /**< how moving instances move */

    uint64_t hash;                /**< content hash of the binary scene */
    void *blob; size_t blob_size; int mapped;
    void *bvh_copy; size_t bvh_copy_size; /**< nodes and leaves in large pages, or NULL (scene_pages.h) */
} fr_scene;

/** Releases the scene's blob (free or munmap) and zeroes *s. */
void scn_free(fr_scene *s);

#endif
