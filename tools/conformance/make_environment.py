#!/usr/bin/python3
"""Writes the conformance environment and the sheen albedo table the reference renderer needs.

tests/data/conformance/environment.hdr: a 512x256 equirectangular Radiance HDR (run-length
encoded RGBE, rows top to bottom, +Y up) with structure that shows in reflections:
  - a sky from a pale horizon to a deep blue zenith,
  - a bright warm window-like rectangle (radiance 6) above the horizon,
  - a smaller red patch a quarter turn away and a green one opposite it, so a mirror ball shows
    which way the map is turned,
  - a brown ground with a darker band near the horizon.
The image's column u (0..1) is azimuth and its row v (0 top .. 1 bottom) is polar angle.

tools/conformance/lut_sheen_E.png: the directional albedo E(cos_v, sheen_roughness) of the
Charlie sheen BRDF (the viewer's D_Charlie and V_Sheen, sheen colour 1), 32x32, red channel,
x = cos_v, y = roughness (row 0 = roughness 0). The glTF Sample Viewer's npm package does not
ship this table; it reads it to scale the base layer under sheen.

Needs python3-numpy and python3-pil. Run from anywhere; the outputs are committed.
"""
import math
import os

import numpy as np
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
OUT_DIR = os.path.join(ROOT, "tests", "data", "conformance")


def environment(width=512, height=256):
    """Linear radiance, float32 [height, width, 3]."""
    v = (np.arange(height) + 0.5) / height
    u = (np.arange(width) + 0.5) / width
    theta = v * math.pi  # polar angle from +Y
    elevation = math.pi / 2 - theta  # radians above the horizon
    img = np.zeros((height, width, 3), np.float32)
    uu, ee = np.meshgrid(u, elevation)

    sky = ee >= 0
    t = np.clip(ee / (math.pi / 2), 0, 1) ** 0.6
    horizon = np.array([0.6, 0.57, 0.55])
    zenith = np.array([0.07, 0.14, 0.42])
    sky_rgb = horizon[None, None, :] * (1 - t[..., None]) + zenith[None, None, :] * t[..., None]
    img[sky] = sky_rgb[sky]

    ground = ~sky
    depth = np.clip(-ee / (math.pi / 2), 0, 1)
    ground_rgb = np.array([0.18, 0.12, 0.07]) * (0.6 + 0.4 * depth[..., None])
    band = (ee < 0) & (ee > -math.radians(8))
    img[ground] = ground_rgb[ground]
    img[band] *= 0.35

    def patch(u0, u1, e0, e1, rgb):
        m = (uu >= u0) & (uu < u1) & (ee >= math.radians(e0)) & (ee < math.radians(e1))
        img[m] = rgb

    patch(0.42, 0.58, 15, 50, (6.0, 5.5, 4.8))  # the window
    patch(0.17, 0.23, 5, 25, (1.6, 0.12, 0.1))  # red, a quarter turn from the window
    patch(0.92, 0.98, 5, 25, (0.1, 1.0, 0.15))  # green, opposite the red patch
    return img


def to_rgbe(img):
    m = img.max(axis=2)
    out = np.zeros(img.shape[:2] + (4,), np.uint8)
    nz = m > 1e-32
    mant, expo = np.frexp(m[nz])
    scale = mant * 256.0 / m[nz]
    out[nz, 0:3] = np.clip(img[nz] * scale[:, None], 0, 255).astype(np.uint8)
    out[nz, 3] = (expo + 128).astype(np.uint8)
    return out


def rle_channel(data):
    """Radiance's run-length encoding of one channel of one scanline."""
    out = bytearray()
    i, n = 0, len(data)
    while i < n:
        run = 1
        while i + run < n and run < 127 and data[i + run] == data[i]:
            run += 1
        if run >= 4:
            out += bytes((128 + run, data[i]))
            i += run
            continue
        start = i
        while i < n and i - start < 128:
            if i + 3 < n and data[i] == data[i + 1] == data[i + 2] == data[i + 3]:
                break
            i += 1
        out += bytes((i - start,)) + bytes(data[start:i])
    return out


def write_hdr(path, img):
    h, w = img.shape[:2]
    rgbe = to_rgbe(img)
    body = bytearray()
    for y in range(h):
        body += bytes((2, 2, (w >> 8) & 0xFF, w & 0xFF))
        for c in range(4):
            body += rle_channel(rgbe[y, :, c].tobytes())
    header = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w)
    write_atomic(path, header + bytes(body))


def write_atomic(path, data):
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def lambda_sheen(cos_theta, alpha_g):
    one_minus_sq = (1 - alpha_g) ** 2
    a = 21.5473 + (25.3245 - 21.5473) * one_minus_sq
    b = 3.82987 + (3.32435 - 3.82987) * one_minus_sq
    c = 0.19823 + (0.16801 - 0.19823) * one_minus_sq
    d = -1.97760 + (-1.27393 + 1.97760) * one_minus_sq
    e = -4.32054 + (-4.85967 + 4.32054) * one_minus_sq

    def helper(x):
        return a / (1 + b * np.power(x, c)) + d * x + e

    return np.where(np.abs(cos_theta) < 0.5, np.exp(helper(cos_theta)),
                    np.exp(2 * helper(0.5) - helper(1 - cos_theta)))


def sheen_albedo(cos_v, roughness, n=256):
    """E = integral over the hemisphere of D_Charlie * V_Sheen * cos_l (midpoint rule)."""
    r = max(roughness, 1e-6)
    alpha_g = r * r
    v = np.array([math.sqrt(max(0.0, 1 - cos_v * cos_v)), 0.0, cos_v])
    th = (np.arange(n) + 0.5) / n * (math.pi / 2)
    ph = (np.arange(2 * n) + 0.5) / (2 * n) * (2 * math.pi)
    tt, pp = np.meshgrid(th, ph, indexing="ij")
    l = np.stack([np.sin(tt) * np.cos(pp), np.sin(tt) * np.sin(pp), np.cos(tt)], -1)
    h = l + v
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    n_dot_h = h[..., 2]
    n_dot_l = np.maximum(l[..., 2], 1e-6)
    n_dot_v = max(cos_v, 1e-6)
    inv_r = 1 / alpha_g
    sin2h = np.maximum(1 - n_dot_h * n_dot_h, 0)
    d = (2 + inv_r) * np.power(sin2h, inv_r * 0.5) / (2 * math.pi)
    vis = 1 / ((1 + lambda_sheen(n_dot_v, alpha_g) + lambda_sheen(n_dot_l, alpha_g)) *
               (4 * n_dot_v * n_dot_l))
    vis = np.clip(vis, 0, 1)
    d_omega = (math.pi / 2 / n) * (2 * math.pi / (2 * n)) * np.sin(tt)
    return float(np.sum(d * vis * n_dot_l * d_omega))


def write_sheen_lut(path, size=32):
    lut = np.zeros((size, size), np.float64)
    for y in range(size):
        for x in range(size):
            lut[y, x] = sheen_albedo((x + 0.5) / size, (y + 0.5) / size)
    img = np.zeros((size, size, 4), np.uint8)
    img[..., 0] = np.clip(np.round(lut * 255), 0, 255).astype(np.uint8)
    img[..., 3] = 255
    tmp = path + ".tmp.png"
    Image.fromarray(img, "RGBA").save(tmp)
    os.replace(tmp, path)


def main():
    os.makedirs(OUT_DIR, exist_ok=True)
    write_hdr(os.path.join(OUT_DIR, "environment.hdr"), environment())
    write_sheen_lut(os.path.join(HERE, "lut_sheen_E.png"))
    print("wrote", os.path.join(OUT_DIR, "environment.hdr"), "and", os.path.join(HERE, "lut_sheen_E.png"))


if __name__ == "__main__":
    main()
