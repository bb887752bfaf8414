# lamps.awk -- writes a scene JSON: a ground lit by an n x n grid of small
# downward emissive quads (street lamps), 4 units up and `spacing` apart,
# centred on the origin, the camera standing near the ground.
#   awk -v n=100 [-v spacing=10] [-v radius=R] [-v sampling=power] [-v size=256]
#       [-v spp=16] [-v seed=1] [-v depth=2] -f lamps.awk
# radius: keep only the lamps within R of the camera (the nearby lamps);
# sampling: the image's light_sampling (tree or power).
BEGIN {
    if (spacing == "") spacing = 10
    if (size == "") size = 256
    if (spp == "") spp = 16
    if (seed == "") seed = 1
    if (depth == "") depth = 2
    if (sampling == "") sampling = "tree"
    cx = 1.3; cz = -2.1
    printf "{\"image\": {\"width\": %d, \"height\": %d, \"spp\": %d, \"max_depth\": %d, \"seed\": %d, ", size, size, spp, depth, seed
    printf "\"light_sampling\": \"%s\"},\n", sampling
    printf " \"camera\": {\"position\": [%g, 1.7, %g], \"target\": [%g, 0.2, %g], \"fov\": 60},\n", cx, cz, cx, cz + 12
    printf " \"materials\": {\"ground\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]},\n"
    printf "   \"lamp\": {\"type\": \"emitter\", \"emission\": [400, 380, 300]}},\n"
    printf " \"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"ground\"}"
    half = (n - 1) / 2
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++) {
            x = (i - half) * spacing; z = (j - half) * spacing
            if (radius != "" && (x - cx) ^ 2 + (z - cz) ^ 2 > radius ^ 2)
                continue
            printf ",\n  {\"type\": \"rect\", \"origin\": [%g, 4, %g], \"edge_u\": [0.5, 0, 0], \"edge_v\": [0, 0, 0.5], \"material\": \"lamp\"}", x - 0.25, z - 0.25
        }
    printf "]}\n"
}
