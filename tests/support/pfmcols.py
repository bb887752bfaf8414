# pfmcols.py -- column means of a PF image, for profiles along a motion.
#
# rows(path): the first channel of a PF (float RGB) image as franja writes
# it ("PF", comment lines, "W H", a negative scale: little-endian, rows
# bottom first), as a list of rows from the image's top.
# columns(path): the mean over the rows of each column's first channel,
# left to right.
# smear(x, lo, hi, travel): the mean coverage of pixel column [x, x + 1)
# by the box [lo, hi) shifted by s uniform in [-travel / 2, travel / 2]
# (a box moving at constant speed across a shutter, seen sharp at its
# middle), by the midpoint rule over 800 shifts.
import struct


def rows(path):
    data, lines = open(path, 'rb').read(), []
    while len(lines) < 3:
        line, data = data.split(b'\n', 1)
        if not line.startswith(b'#'):
            lines.append(line)
    w, h = (int(v) for v in lines[1].split())
    vals = struct.unpack('<%df' % (3 * w * h), data[:12 * w * h])
    return [[vals[3 * ((h - 1 - y) * w + x)] for x in range(w)] for y in range(h)]


def columns(path):
    r = rows(path)
    return [sum(row[x] for row in r) / len(r) for x in range(len(r[0]))]


def smear(x, lo, hi, travel, n=800):
    total = 0.0
    for k in range(n):
        s = travel * ((k + 0.5) / n - 0.5)
        total += max(0.0, min(x + 1, hi + s) - max(x, lo + s))
    return total / n


def smear_report(sharp, blur, lo, hi, travel, sharp_tol=0.01):
    """Prints what the motion blur tests check of column profiles: `sharp`
    (the box [lo, hi) without a shutter, within sharp_tol), `smear` (the blurred
    profile within 0.06 of smear()), `total` (the box's coverage kept, within
    0.1) and `spread` (the columns above 0.01, blurred and sharp)."""
    n = len(blur)
    worst = max(abs(blur[x] - smear(x, lo, hi, travel)) for x in range(n))
    print("sharp", all(abs(sharp[x] - (1.0 if lo <= x < hi else 0.0)) < sharp_tol for x in range(n)))
    print("smear", worst < 0.06, worst)
    print("total", abs(sum(blur) - (hi - lo)) < 0.1, sum(blur))
    print("spread", sum(1 for v in blur if v > 0.01), sum(1 for v in sharp if v > 0.01))
