#!/usr/bin/env python3
"""Image metrics for shadel's PNG output, standard library only: PSNR between two images and
mean frame-to-frame difference (flicker) over a directory of frames.

  tools/imgdiff.py psnr A.png B.png
  tools/imgdiff.py flicker DIR/          (frame_0000.png, frame_0001.png, ...)
  tools/imgdiff.py diffmap A.png B.png OUT.png   (per-pixel |A-B| x4, for eyes)
"""
import math, os, struct, sys, zlib


def read_png(path):
    data = open(path, 'rb').read()
    assert data[:8] == b'\x89PNG\r\n\x1a\n', path
    pos, idat, w = 8, b'', 0
    while pos < len(data):
        n, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b'IHDR':
            w, h, depth, ctype = struct.unpack('>IIBB', body[:10])
            assert depth == 8 and ctype in (2, 6), 'RGB/RGBA 8-bit only'
            ch = 3 if ctype == 2 else 4
        elif kind == b'IDAT':
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride = w * ch
    out = bytearray(h * stride)
    prev = bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - ch] if i >= ch else 0
            b = prev[i]
            c = prev[i - ch] if i >= ch else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pr = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pr) & 255
        out[y * stride:(y + 1) * stride] = line
        prev = line
    rgb = bytearray()
    for i in range(0, len(out), ch):
        rgb += out[i:i + 3]
    return w, h, rgb


def write_png(path, w, h, rgb):
    raw = b''.join(b'\x00' + bytes(rgb[y * w * 3:(y + 1) * w * 3]) for y in range(h))
    def chunk(kind, body):
        return struct.pack('>I', len(body)) + kind + body + struct.pack('>I', zlib.crc32(kind + body))
    open(path, 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 2, 0, 0, 0)) +
                           chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b''))


def psnr(a, b):
    se = sum((x - y) ** 2 for x, y in zip(a, b))
    mse = se / len(a)
    return 99.0 if mse == 0 else 10 * math.log10(255 * 255 / mse)


def main():
    cmd = sys.argv[1]
    if cmd == 'psnr':
        _, _, a = read_png(sys.argv[2]); _, _, b = read_png(sys.argv[3])
        print('%.2f' % psnr(a, b))
    elif cmd == 'flicker':
        d = sys.argv[2]
        frames = sorted(f for f in os.listdir(d) if f.endswith('.png'))
        imgs = [read_png(os.path.join(d, f))[2] for f in frames]
        total = sum(sum(abs(x - y) for x, y in zip(imgs[i - 1], imgs[i])) for i in range(1, len(imgs)))
        print('%.4f' % (total / ((len(imgs) - 1) * len(imgs[0]))))
    elif cmd == 'diffmap':
        w, h, a = read_png(sys.argv[2]); _, _, b = read_png(sys.argv[3])
        write_png(sys.argv[4], w, h, bytearray(min(255, abs(x - y) * 4) for x, y in zip(a, b)))
    else:
        sys.exit(__doc__)


if __name__ == '__main__':
    main()
