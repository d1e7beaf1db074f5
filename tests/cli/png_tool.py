"""Small PNG reader for the command-line tests (8-bit RGB/RGBA, no numpy needed).

  png_tool.py black-border FILE      share of black pixels on the ring 1 px inside the border
  png_tool.py mean-abs-diff A B      mean absolute difference per channel value
  png_tool.py size FILE              width and height
  png_tool.py distinct FILE X Y W H  distinct colours in a rectangle (text and images: many)
"""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, 'rb').read()
    i, idat = 8, b''
    while i < len(data):
        n, kind = struct.unpack('>I4s', data[i:i + 8])
        chunk = data[i + 8:i + 8 + n]
        i += 12 + n
        if kind == b'IHDR':
            w, h, bits, colour = struct.unpack('>IIBB', chunk[:10])
        elif kind == b'IDAT':
            idat += chunk
    raw = zlib.decompress(idat)
    bpp = 3 if colour == 2 else 4
    stride = w * bpp
    rows, prev = [], bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return w, h, bpp, rows


def black_border(path):
    w, h, bpp, rows = read_png(path)
    ring = [(1, x) for x in range(1, w - 1)] + [(h - 2, x) for x in range(1, w - 1)] + \
           [(y, 1) for y in range(2, h - 2)] + [(y, w - 2) for y in range(2, h - 2)]
    return sum(1 for y, x in ring if sum(rows[y][x * bpp:x * bpp + 3]) == 0) / len(ring)


def mean_abs_diff(a, b):
    wa, ha, bpa, ra = read_png(a)
    wb, hb, bpb, rb = read_png(b)
    assert (wa, ha, bpa) == (wb, hb, bpb), 'images differ in size'
    total = sum(sum(abs(p - q) for p, q in zip(x, y)) for x, y in zip(ra, rb))
    return total / (wa * ha * bpa)


def distinct(path, x0, y0, w, h):
    _, _, bpp, rows = read_png(path)
    return len({bytes(rows[y][x * bpp:x * bpp + 3]) for y in range(y0, y0 + h) for x in range(x0, x0 + w)})


if __name__ == '__main__':
    if sys.argv[1] == 'black-border':
        print('%.4f' % black_border(sys.argv[2]))
    elif sys.argv[1] == 'mean-abs-diff':
        print('%.4f' % mean_abs_diff(sys.argv[2], sys.argv[3]))
    elif sys.argv[1] == 'size':
        print('%d %d' % read_png(sys.argv[2])[:2])
    elif sys.argv[1] == 'distinct':
        print(distinct(sys.argv[2], *map(int, sys.argv[3:7])))
    else:
        sys.exit('unknown command ' + sys.argv[1])
