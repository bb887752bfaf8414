# facade.awk -- writes a scene JSON, its mesh and its texture: a ground
# lit by the facade of a building at night, 40 wide and 20 high, one
# emitter whose emission texture (512 x 256, dir/facade.ppm) is black but
# for small lit windows (3 x 3 texels, about 1 % of the texture), the facade
# a grid of 32 x 16 squares of two triangles (dir/facade.obj: each triangle
# spans 16 x 16 texels, so a few points of it miss most windows); the camera
# stands on the ground before it.
#   awk -v dir=DIR [-v sampling=power] [-v size=256] [-v spp=16] [-v depth=2] -f facade.awk
BEGIN {
    if (size == "") size = 256
    if (spp == "") spp = 16
    if (depth == "") depth = 2
    if (sampling == "") sampling = "tree"
    srand(7)
    W = 512; H = 256; NX = 32; NY = 16
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++)
            lit[x, y] = 0
    # One or two windows a cell, a third of them lit.
    for (cy = 0; cy < NY; cy++)
        for (cx = 0; cx < NX; cx++) {
            nw = rand() < 0.5 ? 1 : 2
            for (k = 0; k < nw; k++) {
                if (rand() >= 1 / 3)
                    continue
                x0 = cx * 16 + int(rand() * 14); y0 = cy * 16 + int(rand() * 14)
                for (y = y0; y < y0 + 3; y++)
                    for (x = x0; x < x0 + 3; x++)
                        lit[x, y] = 1
            }
        }
    tex = dir "/facade.ppm"
    printf "P3\n%d %d\n255\n", W, H >tex
    for (y = 0; y < H; y++) {
        line = ""
        for (x = 0; x < W; x++)
            line = line (lit[x, y] ? "255 230 180 " : "0 0 0 ")
        print line >tex
    }
    close(tex)
    # The facade in the plane z = 30, from x = -20 to 20 and y = 0 to 20,
    # facing -z (toward the camera); v = 0 is the image's bottom row.
    obj = dir "/facade.obj"
    for (j = 0; j <= NY; j++)
        for (i = 0; i <= NX; i++) {
            printf "v %g %g 30\n", -20 + 40 * i / NX, 20 * j / NY >obj
            printf "vt %g %g\n", i / NX, j / NY >obj
        }
    for (j = 0; j < NY; j++)
        for (i = 0; i < NX; i++) {
            a = j * (NX + 1) + i + 1; b = a + 1; c = a + NX + 1; d = c + 1
            printf "f %d/%d %d/%d %d/%d\n", a, a, c, c, b, b >obj
            printf "f %d/%d %d/%d %d/%d\n", b, b, c, c, d, d >obj
        }
    close(obj)
    printf "{\"image\": {\"width\": %d, \"height\": %d, \"spp\": %d, \"max_depth\": %d, ", size, size, spp, depth
    printf "\"light_sampling\": \"%s\"},\n", sampling
    printf " \"camera\": {\"position\": [0, 1.7, 0], \"target\": [0, 1.2, 12], \"fov\": 60},\n"
    printf " \"textures\": {\"windows\": {\"type\": \"image\", \"file\": \"facade.ppm\"}},\n"
    printf " \"materials\": {\"ground\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]},\n"
    printf "   \"facade\": {\"type\": \"emitter\", \"emission\": {\"texture\": \"windows\", \"factor\": [40, 40, 40]}}},\n"
    printf " \"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"ground\"},\n"
    printf "  {\"type\": \"mesh\", \"file\": \"facade.obj\", \"material\": \"facade\"}]}\n"
}
