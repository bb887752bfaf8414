"""pfmrel.py -- relative RMS difference of two PF images over a band of rows.

    python3 pfmrel.py A.pfm B.pfm [Y0 Y1]

Prints sqrt(mean((a - b)^2)) / mean((a + b) / 2) over every channel of
rows [Y0, Y1) counted from the top (default: the bottom half), and the
band's mean.  Of two renders with different seeds it is sqrt(2) times
the relative noise of one.
"""
import struct
import sys


def read(path):
    with open(path, "rb") as f:
        data = f.read()
    parts, pos = [], 0
    while len(parts) < 4:
        end = data.index(b"\n", pos)
        line = data[pos:end].split(b"#")[0].strip()
        pos = end + 1
        if line:
            parts.extend(line.split())
    w, h, scale = int(parts[1]), int(parts[2]), float(parts[3])
    fmt = ("<" if scale < 0 else ">") + "%df" % (w * h * 3)
    px = struct.unpack(fmt, data[pos:pos + w * h * 12])
    return w, h, px


def main():
    wa, ha, a = read(sys.argv[1])
    wb, hb, b = read(sys.argv[2])
    assert (wa, ha) == (wb, hb), "sizes differ"
    y0 = int(sys.argv[3]) if len(sys.argv) > 3 else ha // 2
    y1 = int(sys.argv[4]) if len(sys.argv) > 4 else ha
    # PF rows run from the bottom: row y from the top is stored at h - 1 - y.
    s2 = sm = 0.0
    n = 0
    for y in range(y0, y1):
        r = (ha - 1 - y) * wa * 3
        for i in range(r, r + wa * 3):
            d = a[i] - b[i]
            s2 += d * d
            sm += 0.5 * (a[i] + b[i])
            n += 1
    mean = sm / n
    print("%.4f %.6g" % ((s2 / n) ** 0.5 / mean if mean > 0 else float("nan"), mean))


main()
