# cloud.awk -- writes a scene JSON: a ground under a cloud of n small
# emissive triangles at random places and orientations (a box 200 wide and
# 30 high from 2 above the ground), the camera standing near the ground.
#   awk -v n=100000 [-v sampling=power] [-v size=256] [-v spp=16] [-v depth=2] -f cloud.awk
BEGIN {
    if (size == "") size = 256
    if (spp == "") spp = 16
    if (depth == "") depth = 2
    if (sampling == "") sampling = "tree"
    srand(31)
    printf "{\"image\": {\"width\": %d, \"height\": %d, \"spp\": %d, \"max_depth\": %d, ", size, size, spp, depth
    printf "\"light_sampling\": \"%s\"},\n", sampling
    printf " \"camera\": {\"position\": [0, 1.7, 0], \"target\": [0, 0.9, 12], \"fov\": 60},\n"
    printf " \"materials\": {\"ground\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]},\n"
    printf "   \"glow\": {\"type\": \"emitter\", \"emission\": [200, 150, 100]}},\n"
    printf " \"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"ground\"}"
    for (i = 0; i < n; i++) {
        x = 200 * rand() - 100; y = 2 + 30 * rand(); z = 200 * rand() - 100
        printf ",\n  {\"type\": \"triangle\", \"vertices\": [[%.3f, %.3f, %.3f], [%.3f, %.3f, %.3f], [%.3f, %.3f, %.3f]], \"material\": \"glow\"}", \
            x, y, z, x + 0.4 * rand() - 0.2, y + 0.4 * rand() - 0.2, z + 0.4 * rand() - 0.2, \
            x + 0.4 * rand() - 0.2, y + 0.4 * rand() - 0.2, z + 0.4 * rand() - 0.2
    }
    printf "]}\n"
}
