#!/usr/bin/env python3
"""Judges renders of builtin:cornell at 640x360 against the reference path tracer's, standard
library only: the mean luminance of screen regions (the floor, the block's faces, the back wall)
in each HDR image (EXR as shadel writes it: 32-bit float channels, ZIP or uncompressed scanlines),
the PSNR of each against the reference once both are tonemapped as the PNGs are (exposure 1,
aces-narkowicz, sRGB, 8 bits), and a side-by-side PNG of them, the reference last.

  tools/reference_regions.py REF.exr [REF2.exr ...] -- NAME=IMG.exr [...] [--side-by-side OUT.png]

Several reference EXRs (independent seeds, the same path count each) are averaged; their
regions' spread is printed as the reference's own noise.
"""
import math, os, struct, sys, zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from imgdiff import write_png, psnr  # noqa: E402

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
    'red wall, in the spot': (20, 110, 60, 170),
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


def display(exr):
    """The 8-bit sRGB pixels the tonemap pass makes of a scene colour (exposure 1, ACES fit)."""
    w, h, planes = exr
    out = bytearray(w * h * 3)
    for i in range(w * h):
        for c, name in enumerate('RGB'):
            x = max(planes[name][i], 0.0)
            y = min(max((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0), 1.0)
            y = y * 12.92 if y < 0.0031308 else 1.055 * y ** (1.0 / 2.4) - 0.055
            out[i * 3 + c] = int(min(max(y, 0.0), 1.0) * 255.0 + 0.5)
    return out


def average(exrs):
    w, h, _ = exrs[0]
    planes = {c: [sum(e[2][c][i] for e in exrs) / len(exrs) for i in range(w * h)]
              for c in 'RGB'}
    return w, h, planes


def main():
    args = sys.argv[1:]
    out = None
    if '--side-by-side' in args:
        k = args.index('--side-by-side')
        out = args[k + 1]
        del args[k:k + 2]
    if '--' not in args:
        sys.exit(__doc__)
    k = args.index('--')
    refs = [read_exr(p) for p in args[:k]]
    runs = [(spec.split('=', 1)[0], read_exr(spec.split('=', 1)[1])) for spec in args[k + 1:]]
    ref = average(refs)
    names = [n for n, _ in runs]
    print('| region | ' + ' | '.join(names) + ' | reference | ' +
          ' | '.join('%s / reference' % n for n in names) + ' |')
    print('| --- ' * (2 * len(names) + 2) + '|')
    for region, rect in REGIONS.items():
        r = region_luminance(ref, rect)
        values = [region_luminance(e, rect) for _, e in runs]
        spread = ''
        if len(refs) > 1:
            each = [region_luminance(e, rect) for e in refs]
            spread = ' (seeds %s)' % ', '.join('%.4f' % v for v in each)
        print('| %s | ' % region + ' | '.join('%.4f' % v for v in values) +
              ' | %.4f%s | ' % (r, spread) + ' | '.join('%.2f' % (v / r) for v in values) + ' |')
    ref_display = display(ref)
    images = []
    for name, exr in runs:
        rgb = display(exr)
        images.append(rgb)
        print('PSNR %s vs reference: %.2f dB' % (name, psnr(rgb, ref_display)))
    if len(refs) > 1:
        print('PSNR reference seed 0 vs seed 1: %.2f dB' %
              psnr(display(refs[0]), display(refs[1])))
    if out:
        w, h, _ = ref
        images.append(ref_display)
        rows = bytearray()
        for y in range(h):
            for rgb in images:
                rows += rgb[y * w * 3:(y + 1) * w * 3]
        write_png(out, w * len(images), h, rows)


if __name__ == '__main__':
    main()
