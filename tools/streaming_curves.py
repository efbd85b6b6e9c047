#!/usr/bin/env python3
"""Texture streaming curves over a walk (render/streaming), standard library only.

  tools/streaming_curves.py [--stride N] STREAMED_STATS.json STREAMED_DIR/ RESIDENT_DIR/ OUT.csv
                            [OUT.png]

Per frame: the cache's resident texture memory (MiB, from the stats' texture_streaming
.resident_bytes_per_frame), its allocated memory (texture_memory_peak_bytes) and the PSNR of the
streamed frame against the same frame with every texture resident (frame_NNNN.png in both
folders; with --stride N frames 0-5, every Nth and the last, linear between: decoding 1280x720 PNGs in pure
Python takes seconds each; after a --camera-cut, the six frames after the cut too). The PNG has two panels: memory (MiB) and PSNR (dB, capped at 60,
the 35 dB line dashed).
"""
import json, math, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from imgdiff import read_png, psnr, write_png  # noqa: E402

# 3x5 glyphs, rows top to bottom, 3 bits each (4 = left).
FONT = {
    '0': [7, 5, 5, 5, 7], '1': [2, 6, 2, 2, 7], '2': [7, 1, 7, 4, 7], '3': [7, 1, 7, 1, 7],
    '4': [5, 5, 7, 1, 1], '5': [7, 4, 7, 1, 7], '6': [7, 4, 7, 5, 7], '7': [7, 1, 1, 1, 1],
    '8': [7, 5, 7, 5, 7], '9': [7, 5, 7, 1, 7], '.': [0, 0, 0, 0, 2], ' ': [0, 0, 0, 0, 0],
    'A': [2, 5, 7, 5, 5], 'B': [6, 5, 6, 5, 6], 'D': [6, 5, 5, 5, 6], 'E': [7, 4, 6, 4, 7],
    'F': [7, 4, 6, 4, 4], 'I': [7, 2, 2, 2, 7], 'L': [4, 4, 4, 4, 7], 'M': [5, 7, 7, 5, 5],
    'N': [6, 5, 5, 5, 5], 'O': [7, 5, 5, 5, 7], 'P': [7, 5, 7, 4, 4], 'R': [6, 5, 6, 5, 5],
    'S': [7, 4, 7, 1, 7], 'T': [7, 2, 2, 2, 2], 'U': [5, 5, 5, 5, 7], 'Y': [5, 5, 2, 2, 2],
    'C': [7, 4, 4, 4, 7], 'G': [7, 4, 5, 5, 7], 'K': [5, 5, 6, 5, 5], 'W': [5, 5, 7, 7, 5],
    '(': [1, 2, 2, 2, 1], ')': [4, 2, 2, 2, 4], '/': [1, 1, 2, 4, 4], '-': [0, 0, 7, 0, 0],
    '>': [4, 2, 1, 2, 4], '=': [0, 7, 0, 7, 0], 'X': [5, 5, 2, 5, 5], 'H': [5, 5, 7, 5, 5],
    'V': [5, 5, 5, 5, 2],
}


class Canvas:
    def __init__(self, w, h):
        self.w, self.h = w, h
        self.px = bytearray([255] * (w * h * 3))

    def dot(self, x, y, c):
        if 0 <= x < self.w and 0 <= y < self.h:
            i = (y * self.w + x) * 3
            self.px[i:i + 3] = bytes(c)

    def line(self, x0, y0, x1, y1, c, dash=0):
        n = max(abs(x1 - x0), abs(y1 - y0), 1)
        for i in range(n + 1):
            if dash and (i // dash) % 2:
                continue
            x = round(x0 + (x1 - x0) * i / n)
            y = round(y0 + (y1 - y0) * i / n)
            for dx in (0, 1):
                self.dot(x + dx, y, c)

    def text(self, x, y, s, c=(0, 0, 0), scale=2):
        for ch in s.upper():
            rows = FONT.get(ch, FONT[' '])
            for r, bits in enumerate(rows):
                for b in range(3):
                    if bits & (4 >> b):
                        for sy in range(scale):
                            for sx in range(scale):
                                self.dot(x + b * scale + sx, y + r * scale + sy, c)
            x += 4 * scale


def panel(cv, top, height, values, lo, hi, title, colour, ref=None):
    left, right = 70, cv.w - 20
    cv.text(left, top - 16, title)
    cv.line(left, top, left, top + height, (0, 0, 0))
    cv.line(left, top + height, right, top + height, (0, 0, 0))
    for k in range(5):
        v = lo + (hi - lo) * k / 4
        y = round(top + height - height * k / 4)
        cv.line(left - 4, y, left, y, (0, 0, 0))
        cv.text(4, y - 5, ('%.0f' % v) if hi - lo >= 8 else ('%.1f' % v))
    n = len(values)

    def xy(i, v):
        x = left + (right - left) * i / max(n - 1, 1)
        y = top + height - height * (min(max(v, lo), hi) - lo) / (hi - lo)
        return round(x), round(y)
    if ref is not None:
        y = xy(0, ref)[1]
        cv.line(left, y, right, y, (120, 120, 120), dash=6)
    for i in range(1, n):
        cv.line(*xy(i - 1, values[i - 1]), *xy(i, values[i]), colour)
    for i in range(0, n, max(n // 6, 1)):
        cv.text(xy(i, lo)[0] - 4, top + height + 6, str(i))


def main():
    args = sys.argv[1:]
    stride = 1
    if args[:1] == ['--stride']:
        stride, args = max(int(args[1]), 1), args[2:]
    stats_path, streamed, resident, csv_path = args[:4]
    stats = json.load(open(stats_path))
    st = stats['texture_streaming']
    memory = [b / 1048576.0 for b in st['resident_bytes_per_frame']]
    allocated = stats['texture_memory_peak_bytes'] / 1048576.0
    frames = len(memory)
    # The first frames densely (convergence from the cold start), then every stride-th.
    measured = set(list(range(min(frames, 6))) + list(range(0, frames, stride)) + [frames - 1])
    # render --camera-cut: the frame before the cut and the six after it densely too.
    cut = stats.get('camera_cut', {}).get('frame')
    if cut is not None:
        measured |= set(range(max(cut - 1, 0), min(cut + 7, frames)))
    measured = sorted(measured)
    db = {}
    for f in measured:
        name = 'frame_%04d.png' % f
        _, _, a = read_png(os.path.join(streamed, name))
        _, _, b = read_png(os.path.join(resident, name))
        db[f] = psnr(a, b)
    with open(csv_path, 'w') as out:
        out.write('frame,resident_mib,allocated_mib,psnr_db\n')
        for f in range(frames):
            out.write('%d,%.3f,%.3f,%s\n' % (f, memory[f], allocated, '%.3f' % db[f] if f in db else ''))
    for f in range(frames):
        print('frame %2d  resident %7.2f MiB (allocated %.2f)  PSNR %s' %
              (f, memory[f], allocated, '%6.2f dB' % db[f] if f in db else '-'))
    # The PSNR curve is linear between measured frames.
    def at(f):
        lo = max(m for m in measured if m <= f)
        hi = min(m for m in measured if m >= f)
        return db[lo] if hi == lo else db[lo] + (db[hi] - db[lo]) * (f - lo) / (hi - lo)
    db = [at(f) for f in range(frames)]
    if len(args) > 4:
        cv = Canvas(800, 520)
        top_mem = max(allocated, max(memory)) * 1.1
        panel(cv, 30, 190, memory, 0.0, top_mem, 'TEXTURE MEMORY MIB (DASHED = ALLOCATED)', (30, 90, 200), ref=allocated)
        finite = [min(d, 60.0) for d in db]
        panel(cv, 290, 190, finite, min(finite) - 1.0 if finite else 0.0, max(max(finite), 36.0) + 1.0,
              'PSNR DB VS ALL RESIDENT (DASHED = 35)', (200, 60, 30), ref=35.0)
        cv.text(340, 505, 'FRAME')
        write_png(args[4], cv.w, cv.h, cv.px)


if __name__ == '__main__':
    main()
