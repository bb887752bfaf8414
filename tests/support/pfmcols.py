# pfmcols.py -- column means of a PF image, for profiles along a motion.
#
# columns(path): the mean over the rows of each column's first channel,
# left to right, of a PF (float RGB) image as franja writes it ("PF",
# comment lines, "W H", a negative scale: little-endian, rows bottom first).
import struct


def columns(path):
    data, lines = open(path, 'rb').read(), []
    while len(lines) < 3:
        line, data = data.split(b'\n', 1)
        if not line.startswith(b'#'):
            lines.append(line)
    w, h = (int(v) for v in lines[1].split())
    vals = struct.unpack('<%df' % (3 * w * h), data[:12 * w * h])
    return [sum(vals[3 * (y * w + x)] for y in range(h)) / h for x in range(w)]
