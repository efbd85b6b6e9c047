#!/usr/bin/env python3
"""Judges renders of builtin:cornell at 640x360 against the reference path tracer's, standard
library only: the mean luminance of screen regions (the floor and the block's faces) in each
HDR image (EXR as shadel writes it: 32-bit float channels, ZIP or uncompressed scanlines), the
PSNR of each PNG against the reference's, and a side-by-side PNG of them all.

  tools/reference_regions.py REF.exr REF.png NAME=IMG.exr,IMG.png [...] [--side-by-side OUT.png]
"""
import math, os, struct, sys, zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from imgdiff import read_png, write_png, psnr  # noqa: E402

# Screen rectangles (x0, y0, x1, y1) of builtin:cornell's main camera at 640x360, each inside
# one surface (the 20-pixel margins keep them off edges).
REGIONS = {
    'floor by the red wall': (70, 270, 170, 340),
    'floor, middle': (240, 200, 360, 250),
    'floor, front right': (430, 300, 560, 350),
    'block, face to the red wall': (392, 175, 412, 250),
    'block, face to the camera': (430, 160, 490, 250),
    'block, top': (425, 110, 480, 125),
    'back wall': (230, 40, 360, 150),
}


def _read_exr_attributes(data):
    pos, attrs = 8, {}
    while data[pos] != 0:
        end = data.index(b'\0', pos)
        name = data[pos:end].decode()
        tend = data.index(b'\0', end + 1)
        kind = data[end + 1:tend].decode()
        size = struct.unpack('<i', data[tend + 1:tend + 5])[0]
        attrs[name] = (kind, data[tend + 5:tend + 5 + size])
        pos = tend + 5 + size
    return attrs, pos + 1


def _channels(value):
    names, pos = [], 0
    while value[pos] != 0:
        end = value.index(b'\0', pos)
        names.append(value[pos:end].decode())
        pixel_type = struct.unpack('<i', value[end + 1:end + 5])[0]
        assert pixel_type == 2, 'float channels only'
        pos = end + 1 + 16
    return names


def _unzip(chunk, expected):
    if len(chunk) == expected:
        return chunk
    t = bytearray(zlib.decompress(chunk))
    for i in range(1, len(t)):
        t[i] = (t[i - 1] + t[i] - 128) & 255
    half = (len(t) + 1) // 2
    out = bytearray(len(t))
    out[0::2] = t[:half]
    out[1::2] = t[half:]
    return bytes(out)


def read_exr(path):
    """(width, height, {channel: [floats]}) of a scanline EXR of float channels."""
    data = open(path, 'rb').read()
    assert data[:4] == b'\x76\x2f\x31\x01', path
    attrs, pos = _read_exr_attributes(data)
    names = _channels(attrs['channels'][1])
    x0, y0, x1, y1 = struct.unpack('<iiii', attrs['dataWindow'][1])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    compression = attrs['compression'][1][0]
    lines_per_block = {0: 1, 2: 1, 3: 16}[compression]
    blocks = (h + lines_per_block - 1) // lines_per_block
    offsets = struct.unpack('<%dQ' % blocks, data[pos:pos + 8 * blocks])
    planes = {n: [0.0] * (w * h) for n in names}
    for offset in offsets:
        y, size = struct.unpack('<ii', data[offset:offset + 8])
        lines = min(lines_per_block, y1 + 1 - y)
        raw = _unzip(data[offset + 8:offset + 8 + size], lines * w * 4 * len(names))
        p = 0
        for line in range(lines):
            row = (y - y0 + line) * w
            for n in names:
                planes[n][row:row + w] = struct.unpack('<%df' % w, raw[p:p + 4 * w])
                p += 4 * w
    return w, h, planes


def region_luminance(exr, rect):
    w, _, planes = exr
    x0, y0, x1, y1 = rect
    total, count = 0.0, 0
    for y in range(y0, y1):
        for x in range(x0, x1):
            i = y * w + x
            total += 0.2126 * planes['R'][i] + 0.7152 * planes['G'][i] + 0.0722 * planes['B'][i]
            count += 1
    return total / count


def main():
    args = sys.argv[1:]
    out = None
    if '--side-by-side' in args:
        k = args.index('--side-by-side')
        out = args[k + 1]
        del args[k:k + 2]
    if len(args) < 3:
        sys.exit(__doc__)
    ref = read_exr(args[0])
    _, _, ref_png = read_png(args[1])
    runs = []
    for spec in args[2:]:
        name, files = spec.split('=', 1)
        exr_path, png_path = files.split(',')
        runs.append((name, read_exr(exr_path), read_png(png_path)))
    names = [n for n, _, _ in runs]
    print('| region | ' + ' | '.join(names) + ' | reference | ' +
          ' | '.join('%s / reference' % n for n in names) + ' |')
    print('| --- ' * (2 * len(names) + 2) + '|')
    for region, rect in REGIONS.items():
        r = region_luminance(ref, rect)
        values = [region_luminance(e, rect) for _, e, _ in runs]
        print('| %s | ' % region + ' | '.join('%.4f' % v for v in values) + ' | %.4f | ' % r +
              ' | '.join('%.2f' % (v / r) for v in values) + ' |')
    for name, _, (_, _, rgb) in runs:
        print('PSNR %s vs reference: %.2f dB' % (name, psnr(rgb, ref_png)))
    if out:
        w, h, _ = runs[0][2]
        images = [png[2] for _, _, png in runs] + [ref_png]
        rows = bytearray()
        for y in range(h):
            for rgb in images:
                rows += rgb[y * w * 3:(y + 1) * w * 3]
        write_png(out, w * len(images), h, rows)


if __name__ == '__main__':
    main()
