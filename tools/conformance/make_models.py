#!/usr/bin/python3
"""Writes the conformance test models into tests/data/conformance/models/NAME/.

Every model carries the view both renderers draw: a perspective camera named "conformance"
(vertical field of view, aspect 16:9) and one KHR_lights_punctual directional light, so the
glTF Sample Viewer (state.cameraIndex) and shadel (--camera conformance) read the same camera
and light from the file.

Two kinds of model:
  - generated scenes (sphere grid, alpha modes, sampler wrap and filter modes, double-sided
    surfaces, clearcoat, sheen, transmission and volume, texture transform, emissive strength),
    written whole: NAME.gltf, NAME.bin and NAME_*.png;
  - wrappers of the assimp glTF2 sample models (/usr/share/assimp/models/glTF2, Debian package
    assimp-testmodels): the model's JSON with the camera and light added and its buffers and
    images referenced by file name. The harness (compare.py, render_reference.js, the GPU test)
    stages a wrapper by linking it and the sample's folder's files into one folder. A binary
    sample (.glb) is wrapped by making the .glb file itself the buffer: bufferViews start at its
    binary chunk's offset.

Also writes the models section of tools/conformance/models.json, keeping the floors already in
it. Needs python3-numpy and python3-pil. Run from anywhere; the outputs are committed.
"""
import json
import math
import os
import struct

import numpy as np
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
MODELS = os.path.join(ROOT, "tests", "data", "conformance", "models")
MANIFEST = os.path.join(HERE, "models.json")
ASSIMP = "/usr/share/assimp/models/glTF2"

ASPECT = 16.0 / 9.0
YFOV = math.radians(40.0)
# The light travels along this direction (from above, left and in front of the scene).
LIGHT_DIRECTION = (0.45, -0.75, -0.5)
LIGHT_INTENSITY = 2.0

FLOAT, USHORT = 5126, 5123
NEAREST, LINEAR = 9728, 9729
NEAREST_MIPMAP_NEAREST, LINEAR_MIPMAP_NEAREST = 9984, 9985
NEAREST_MIPMAP_LINEAR, LINEAR_MIPMAP_LINEAR = 9986, 9987
REPEAT, CLAMP, MIRRORED = 10497, 33071, 33648


def write_atomic(path, data):
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def normalize(v):
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v)


def quat_from_matrix(m):
    """Unit quaternion (x, y, z, w) of a 3x3 rotation matrix."""
    t = m[0, 0] + m[1, 1] + m[2, 2]
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        q = ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = (0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s)
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = ((m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s)
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = ((m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s, (m[1, 0] - m[0, 1]) / s)
    q = normalize(q)
    return [round(float(c), 7) for c in q]


def rotation_towards(direction, up=(0, 1, 0)):
    """Node rotation turning -Z onto `direction` with +Y as close to `up` as it can be."""
    f = normalize(direction)
    if abs(np.dot(f, normalize(up))) > 0.999:
        up = (0, 0, 1)
    r = normalize(np.cross(f, up))
    u = np.cross(r, f)
    return quat_from_matrix(np.stack([r, u, -f], axis=1))


def view_nodes(eye, target, znear, zfar):
    """The camera and light nodes (JSON), the camera and the light definitions."""
    camera = {"name": "conformance", "type": "perspective",
              "perspective": {"yfov": round(YFOV, 7), "aspectRatio": round(ASPECT, 7),
                              "znear": znear, "zfar": zfar}}
    light = {"name": "conformance_sun", "type": "directional", "color": [1.0, 1.0, 1.0],
             "intensity": LIGHT_INTENSITY}
    cam_node = {"name": "conformance", "camera": 0,
                "translation": [round(float(c), 6) for c in eye],
                "rotation": rotation_towards(np.subtract(target, eye))}
    light_node = {"name": "conformance_sun", "rotation": rotation_towards(LIGHT_DIRECTION),
                  "extensions": {"KHR_lights_punctual": {"light": 0}}}
    return cam_node, light_node, camera, light


def project(eye, target, point):
    """Normalized image position (x right, y down, 0..1) of a world point."""
    f = normalize(np.subtract(target, eye))
    r = normalize(np.cross(f, (0, 1, 0)))
    u = np.cross(r, f)
    d = np.subtract(point, eye)
    z = np.dot(d, f)
    t = math.tan(YFOV / 2)
    x = np.dot(d, r) / (z * t * ASPECT)
    y = np.dot(d, u) / (z * t)
    return (0.5 + 0.5 * x, 0.5 - 0.5 * y, z)


# ---- geometry ---------------------------------------------------------------------------------

def uv_sphere(radius=0.4, segments=40, rings=20):
    pos, nrm, uv = [], [], []
    for j in range(rings + 1):
        v = j / rings
        th = v * math.pi
        for i in range(segments + 1):
            u = i / segments
            ph = u * 2 * math.pi
            n = (math.sin(th) * math.sin(ph), math.cos(th), math.sin(th) * math.cos(ph))
            nrm.append(n)
            pos.append(tuple(radius * c for c in n))
            uv.append((u, v))
    idx = []
    for j in range(rings):
        for i in range(segments):
            a = j * (segments + 1) + i
            b = a + segments + 1
            idx += [a, b, a + 1, a + 1, b, b + 1]
    return pos, nrm, uv, idx


def quad(width, height, uv0=(0.0, 0.0), uv1=(1.0, 1.0)):
    """A quad in the XY plane facing +Z; uv0 at the top-left corner, uv1 at the bottom-right."""
    w, h = width / 2, height / 2
    pos = [(-w, h, 0), (w, h, 0), (w, -h, 0), (-w, -h, 0)]
    nrm = [(0, 0, 1)] * 4
    uv = [(uv0[0], uv0[1]), (uv1[0], uv0[1]), (uv1[0], uv1[1]), (uv0[0], uv1[1])]
    return pos, nrm, uv, [0, 3, 1, 1, 3, 2]


def open_tube(radius=0.55, length=1.6, segments=48):
    """A cylinder along Y without caps, normals outward, triangles counter-clockwise outside."""
    pos, nrm, uv = [], [], []
    for j in range(2):
        y = (0.5 - j) * length
        for i in range(segments + 1):
            a = i / segments * 2 * math.pi
            n = (math.sin(a), 0.0, math.cos(a))
            pos.append((radius * n[0], y, radius * n[2]))
            nrm.append(n)
            uv.append((i / segments, j))
    idx = []
    for i in range(segments):
        a, b = i, i + segments + 1
        idx += [a, b, a + 1, a + 1, b, b + 1]
    return pos, nrm, uv, idx


# ---- images -----------------------------------------------------------------------------------

def marker_texture(size=16):
    """Asymmetric: red grows with u, green with v, a dark L in the top-left corner, so every
    wrap mode and every flip of an axis shows."""
    img = np.zeros((size, size, 4), np.uint8)
    for y in range(size):
        for x in range(size):
            img[y, x] = (40 + 200 * x // (size - 1), 40 + 200 * y // (size - 1), 150, 255)
    q = size // 4
    img[1:size // 2, 1:1 + q // 2 + 1] = (20, 20, 20, 255)
    img[size // 2 - q // 2 - 1:size // 2, 1:size // 2] = (20, 20, 20, 255)
    return img


def checker(size, cells, a=(230, 230, 230), b=(40, 40, 40)):
    img = np.zeros((size, size, 4), np.uint8)
    c = size // cells
    for y in range(size):
        for x in range(size):
            img[y, x, :3] = a if ((x // c) + (y // c)) % 2 == 0 else b
    img[..., 3] = 255
    return img


def fine_pattern(size=128):
    """High-frequency coloured stripes and checks: its mip levels average to other colours, so
    the minification filters differ."""
    img = np.zeros((size, size, 4), np.uint8)
    for y in range(size):
        for x in range(size):
            if (x // 2 + y // 2) % 2 == 0:
                img[y, x, :3] = (250, 200, 40) if (x // 16) % 2 == 0 else (40, 120, 250)
            else:
                img[y, x, :3] = (20, 20, 20)
    img[..., 3] = 255
    return img


def alpha_ramp(size=64):
    """RGB checker, alpha rising left to right from 0 to 1, with a fully opaque disc."""
    img = checker(size, 8, (240, 180, 60), (60, 160, 240))
    ramp = np.linspace(0, 255, size).astype(np.uint8)
    img[..., 3] = ramp[None, :]
    yy, xx = np.mgrid[0:size, 0:size]
    disc = (xx - size * 0.25) ** 2 + (yy - size * 0.5) ** 2 < (size * 0.15) ** 2
    img[disc, 3] = 255
    return img


# ---- glTF writer ------------------------------------------------------------------------------

class Gltf:
    def __init__(self, name):
        self.name = name
        self.bin = bytearray()
        self.images = {}
        self.geometries = {}
        self.doc = {"asset": {"version": "2.0",
                              "generator": "shadel tools/conformance/make_models.py"},
                    "scene": 0, "scenes": [{"name": name, "nodes": []}], "nodes": [],
                    "meshes": [], "materials": [], "accessors": [], "bufferViews": [],
                    "buffers": [], "extensionsUsed": ["KHR_lights_punctual"]}

    def use(self, extension):
        if extension not in self.doc["extensionsUsed"]:
            self.doc["extensionsUsed"].append(extension)

    def _view(self, data, target):
        while len(self.bin) % 4:
            self.bin.append(0)
        view = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if target:
            view["target"] = target
        self.bin += data
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, values, type_, minmax=False):
        arr = np.asarray(values, np.float32)
        view = self._view(arr.tobytes(), 34962)
        acc = {"bufferView": view, "componentType": FLOAT, "count": len(arr), "type": type_}
        if minmax:
            acc["min"] = [float(c) for c in arr.min(axis=0)]
            acc["max"] = [float(c) for c in arr.max(axis=0)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def mesh(self, geometry, material, name):
        """A mesh of one primitive; meshes of the same geometry share its accessors."""
        key = id(geometry)
        if key not in self.geometries:
            pos, nrm, uv, idx = geometry
            p = self._accessor(pos, "VEC3", True)
            n = self._accessor(nrm, "VEC3")
            t = self._accessor(uv, "VEC2")
            iview = self._view(np.asarray(idx, np.uint16).tobytes(), 34963)
            self.doc["accessors"].append({"bufferView": iview, "componentType": USHORT,
                                          "count": len(idx), "type": "SCALAR"})
            self.geometries[key] = (geometry, p, n, t, len(self.doc["accessors"]) - 1)
        _, p, n, t, i = self.geometries[key]
        self.doc["meshes"].append({"name": name, "primitives": [{
            "attributes": {"POSITION": p, "NORMAL": n, "TEXCOORD_0": t}, "indices": i,
            "material": material}]})
        return len(self.doc["meshes"]) - 1

    def material(self, mat):
        self.doc["materials"].append(mat)
        return len(self.doc["materials"]) - 1

    def texture(self, image_name, pixels, sampler):
        if image_name not in self.images:
            uri = f"{self.name}_{image_name}.png"
            self.doc.setdefault("images", []).append({"uri": uri})
            self.images[image_name] = (len(self.doc["images"]) - 1, pixels)
        self.doc.setdefault("samplers", []).append(sampler)
        self.doc.setdefault("textures", []).append(
            {"source": self.images[image_name][0], "sampler": len(self.doc["samplers"]) - 1})
        return len(self.doc["textures"]) - 1

    def node(self, mesh, translation=(0, 0, 0), rotation=None, name=None):
        n = {"mesh": mesh, "translation": [round(float(c), 6) for c in translation]}
        if rotation is not None:
            n["rotation"] = [round(float(c), 7) for c in rotation]
        if name:
            n["name"] = name
        self.doc["nodes"].append(n)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def write(self, eye, target):
        dist = float(np.linalg.norm(np.subtract(target, eye)))
        cam_node, light_node, camera, light = view_nodes(eye, target, round(dist * 0.05, 4),
                                                         round(dist * 10, 2))
        self.doc["cameras"] = [camera]
        self.doc["extensions"] = {"KHR_lights_punctual": {"lights": [light]}}
        for n in (cam_node, light_node):
            self.doc["nodes"].append(n)
            self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)
        folder = os.path.join(MODELS, self.name)
        os.makedirs(folder, exist_ok=True)
        self.doc["buffers"] = [{"uri": f"{self.name}.bin", "byteLength": len(self.bin)}]
        write_atomic(os.path.join(folder, f"{self.name}.bin"), bytes(self.bin))
        for image_name, (_, pixels) in self.images.items():
            path = os.path.join(folder, f"{self.name}_{image_name}.png")
            Image.fromarray(pixels, "RGBA").save(path + ".tmp.png", optimize=True)
            os.replace(path + ".tmp.png", path)
        text = json.dumps(self.doc, indent=1) + "\n"
        write_atomic(os.path.join(folder, f"{self.name}.gltf"), text.encode())
        return f"tests/data/conformance/models/{self.name}/{self.name}.gltf"


def pbr(base, metallic, roughness, **extra):
    m = {"pbrMetallicRoughness": {"baseColorFactor": list(base), "metallicFactor": metallic,
                                  "roughnessFactor": roughness}}
    m.update(extra)
    return m


# ---- generated scenes -------------------------------------------------------------------------

def sphere_grid():
    g = Gltf("sphere_grid")
    sphere = uv_sphere(0.42)
    eye, target = (0.0, 0.0, 8.0), (0.0, 0.0, 0.0)
    metal_regions = []
    for row, metallic in enumerate((0.0, 0.25, 0.5, 0.75, 1.0)):
        for col, roughness in enumerate((0.0, 0.25, 0.5, 0.75, 1.0)):
            name = f"m{metallic:.2f}_r{roughness:.2f}"
            mat = g.material(dict(name=name, **pbr((0.95, 0.64, 0.54, 1.0), metallic, roughness)))
            pos = ((col - 2) * 1.05, (2 - row) * 1.0, 0.0)
            g.node(g.mesh(sphere, mat, name), pos, name=name)
            if metallic == 1.0:
                cx, cy, z = project(eye, target, pos)
                r = 0.42 / (z * math.tan(YFOV / 2)) * 0.5
                metal_regions.append([round(cx, 5), round(cy, 5), round(r * 0.85, 5)])
    return g.write(eye, target), {"metal_regions": metal_regions}


def alpha_modes():
    g = Gltf("alpha_modes")
    tex = lambda: {"index": g.texture("ramp", alpha_ramp(), {"magFilter": LINEAR,
                                                             "minFilter": LINEAR_MIPMAP_LINEAR})}
    white = (1.0, 1.0, 1.0, 1.0)
    opaque = g.material({"name": "opaque", "alphaMode": "OPAQUE", "pbrMetallicRoughness": {
        "baseColorFactor": list(white), "baseColorTexture": tex(), "metallicFactor": 0.0,
        "roughnessFactor": 0.6}})
    mask = g.material({"name": "mask", "alphaMode": "MASK", "alphaCutoff": 0.5,
                       "pbrMetallicRoughness": {"baseColorFactor": list(white),
                                                "baseColorTexture": tex(), "metallicFactor": 0.0,
                                                "roughnessFactor": 0.6}})
    blend = g.material({"name": "blend_ramp", "alphaMode": "BLEND", "pbrMetallicRoughness": {
        "baseColorFactor": list(white), "baseColorTexture": tex(), "metallicFactor": 0.0,
        "roughnessFactor": 0.6}})
    red = g.material(dict(name="blend_red", alphaMode="BLEND",
                          **pbr((0.9, 0.1, 0.1, 0.5), 0.0, 0.5)))
    blue = g.material(dict(name="blend_blue", alphaMode="BLEND",
                           **pbr((0.1, 0.3, 0.9, 0.4), 0.0, 0.5)))
    back = g.material(dict(name="backdrop", **pbr((0.8, 0.8, 0.8, 1.0), 0.0, 0.9)))
    g.node(g.mesh(quad(1.6, 1.6), opaque, "opaque"), (-2.7, 0.9, 0), name="opaque")
    g.node(g.mesh(quad(1.6, 1.6), mask, "mask"), (-0.9, 0.9, 0), name="mask")
    g.node(g.mesh(quad(1.6, 1.6), blend, "blend_ramp"), (0.9, 0.9, 0), name="blend_ramp")
    g.node(g.mesh(quad(2.4, 1.9), back, "backdrop"), (1.8, -0.5, -0.6), name="backdrop")
    g.node(g.mesh(quad(1.3, 1.3), red, "blend_red"), (1.3, -0.35, 0.0), name="blend_red")
    g.node(g.mesh(quad(1.3, 1.3), blue, "blend_blue"), (2.0, -0.75, 0.4), name="blend_blue")
    g.node(g.mesh(quad(1.3, 1.3), mask, "mask_low"), (-1.8, -0.9, 0), name="mask_low")
    return g.write((-0.2, 0.0, 6.2), (-0.2, 0.0, 0.0)), {}


def sampler_wrap():
    g = Gltf("sampler_wrap")
    modes = [(REPEAT, REPEAT), (MIRRORED, MIRRORED), (CLAMP, CLAMP),
             (REPEAT, CLAMP), (CLAMP, MIRRORED), (MIRRORED, REPEAT)]
    names = {REPEAT: "repeat", MIRRORED: "mirrored", CLAMP: "clamp"}
    geometry = quad(1.5, 1.5, (-1.0, -1.0), (2.0, 2.0))
    for k, (s, t) in enumerate(modes):
        name = f"s_{names[s]}_t_{names[t]}"
        texture = g.texture("marker", marker_texture(), {"magFilter": LINEAR,
                                                         "minFilter": LINEAR_MIPMAP_LINEAR,
                                                         "wrapS": s, "wrapT": t})
        mat = g.material({"name": name, "pbrMetallicRoughness": {
            "baseColorTexture": {"index": texture}, "metallicFactor": 0.0,
            "roughnessFactor": 0.8}})
        g.node(g.mesh(geometry, mat, name), ((k % 3 - 1) * 1.75, (0.5 - k // 3) * 1.7, 0),
               name=name)
    return g.write((0.0, 0.0, 5.2), (0.0, 0.0, 0.0)), {}


def sampler_filter():
    g = Gltf("sampler_filter")
    names = {NEAREST: "nearest", LINEAR: "linear",
             NEAREST_MIPMAP_NEAREST: "nearest_mipmap_nearest",
             LINEAR_MIPMAP_NEAREST: "linear_mipmap_nearest",
             NEAREST_MIPMAP_LINEAR: "nearest_mipmap_linear",
             LINEAR_MIPMAP_LINEAR: "linear_mipmap_linear"}

    def textured(name, image, pixels, sampler):
        tex = g.texture(image, pixels, sampler)
        return g.material({"name": name, "pbrMetallicRoughness": {
            "baseColorTexture": {"index": tex}, "metallicFactor": 0.0, "roughnessFactor": 0.8}})

    big = quad(2.2, 2.2)
    for k, mag in enumerate((NEAREST, LINEAR)):
        name = f"mag_{names[mag]}"
        mat = textured(name, "checker8", marker_texture(8), {"magFilter": mag,
                                                            "minFilter": LINEAR})
        g.node(g.mesh(big, mat, name), ((k - 0.5) * 2.5, 1.0, 0), name=name)
    small = quad(0.95, 0.95)
    for k, mn in enumerate((NEAREST, LINEAR, NEAREST_MIPMAP_NEAREST, LINEAR_MIPMAP_NEAREST,
                            NEAREST_MIPMAP_LINEAR, LINEAR_MIPMAP_LINEAR)):
        name = f"min_{names[mn]}"
        mat = textured(name, "fine", fine_pattern(), {"magFilter": LINEAR, "minFilter": mn})
        g.node(g.mesh(small, mat, name), ((k - 2.5) * 1.05, -0.95, 0), name=name)
    return g.write((0.0, 0.3, 5.6), (0.0, 0.3, 0.0)), {}


def double_sided():
    g = Gltf("double_sided")
    tube = open_tube()
    tilt = quat_from_matrix(rotation_matrix_x(math.radians(55)))
    for k, double in enumerate((True, False)):
        name = "double_sided" if double else "single_sided"
        mat = g.material(dict(name=name, doubleSided=double,
                              **pbr((0.25, 0.6, 0.9, 1.0), 0.0, 0.45)))
        g.node(g.mesh(tube, mat, name + "_tube"), ((k - 0.5) * 2.2, 0.3, 0), tilt,
               name=name + "_tube")
        sheet = g.material(dict(name=name + "_sheet", doubleSided=double,
                                **pbr((0.9, 0.75, 0.3, 1.0), 0.0, 0.5)))
        turn = quat_from_matrix(rotation_matrix_y(math.radians(125 if k == 0 else -125)))
        g.node(g.mesh(quad(1.2, 0.9), sheet, name + "_sheet"), ((k - 0.5) * 2.2, -1.15, 0),
               turn, name=name + "_sheet")
    return g.write((0.0, 0.55, 4.6), (0.0, -0.15, 0.0)), {}


def rotation_matrix_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rotation_matrix_y(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def sphere_row(name, materials, eye=(0.0, 0.0, 6.0), spacing=1.1, rows=1):
    g = Gltf(name)
    sphere = uv_sphere(0.48)
    per_row = (len(materials) + rows - 1) // rows
    for k, make in enumerate(materials):
        mat = g.material(make(g))
        label = g.doc["materials"][mat]["name"]
        x = (k % per_row - (per_row - 1) / 2) * spacing
        y = ((rows - 1) / 2 - k // per_row) * spacing
        g.node(g.mesh(sphere, mat, label), (x, y, 0), name=label)
    return g


def clearcoat():
    mats = []
    for cc_rough in (0.0, 0.4):
        for cc in (0.0, 0.5, 1.0):
            def make(g, cc=cc, cc_rough=cc_rough):
                g.use("KHR_materials_clearcoat")
                return dict(name=f"cc{cc:.1f}_r{cc_rough:.1f}",
                            extensions={"KHR_materials_clearcoat": {
                                "clearcoatFactor": cc, "clearcoatRoughnessFactor": cc_rough}},
                            **pbr((0.8, 0.08, 0.05, 1.0), 0.0, 0.6))
            mats.append(make)
    g = sphere_row("clearcoat", mats, rows=2)
    return g.write((0.0, 0.0, 3.9), (0.0, 0.0, 0.0)), {}


def sheen():
    mats = [lambda g: dict(name="no_sheen", **pbr((0.08, 0.08, 0.25, 1.0), 0.0, 0.8))]
    for rough in (0.25, 0.6, 1.0):
        def make(g, rough=rough):
            g.use("KHR_materials_sheen")
            return dict(name=f"sheen_r{rough:.2f}", extensions={"KHR_materials_sheen": {
                "sheenColorFactor": [1.0, 0.55, 0.5], "sheenRoughnessFactor": rough}},
                **pbr((0.08, 0.08, 0.25, 1.0), 0.0, 0.8))
        mats.append(make)
    g = sphere_row("sheen", mats)
    return g.write((0.0, 0.0, 3.9), (0.0, 0.0, 0.0)), {}


def transmission():
    g = Gltf("transmission")
    g.use("KHR_materials_transmission")
    g.use("KHR_materials_volume")
    tex = g.texture("checker", checker(64, 8, (230, 200, 60), (40, 60, 160)),
                    {"magFilter": LINEAR, "minFilter": LINEAR_MIPMAP_LINEAR})
    back = g.material({"name": "backdrop", "pbrMetallicRoughness": {
        "baseColorTexture": {"index": tex}, "metallicFactor": 0.0, "roughnessFactor": 0.8}})
    g.node(g.mesh(quad(6.0, 3.0), back, "backdrop"), (0, 0, -1.2), name="backdrop")
    sphere = uv_sphere(0.6)
    variants = [
        ("thin", {"KHR_materials_transmission": {"transmissionFactor": 1.0}}, 0.0),
        ("volume", {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                    "KHR_materials_volume": {"thicknessFactor": 1.2,
                                             "attenuationColor": [0.95, 0.55, 0.2],
                                             "attenuationDistance": 0.6}}, 0.0),
        ("rough_volume", {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                          "KHR_materials_volume": {"thicknessFactor": 1.2}}, 0.35),
    ]
    for k, (name, ext, rough) in enumerate(variants):
        mat = g.material(dict(name=name, extensions=ext, **pbr((1.0, 1.0, 1.0, 1.0), 0.0, rough)))
        g.node(g.mesh(sphere, mat, name), ((k - 1) * 1.6, 0, 0), name=name)
    return g.write((0.0, 0.3, 5.0), (0.0, 0.0, 0.0)), {}


def texture_transform():
    g = Gltf("texture_transform")
    g.use("KHR_texture_transform")
    transforms = [("none", None), ("offset", {"offset": [0.5, 0.25]}),
                  ("rotation", {"rotation": 0.6}), ("scale", {"scale": [2.0, 3.0]}),
                  ("all", {"offset": [0.2, -0.1], "rotation": -0.4, "scale": [1.5, 0.75]}),
                  ("texcoord", {"texCoord": 0, "scale": [0.5, 0.5]})]
    for k, (name, tt) in enumerate(transforms):
        tex = g.texture("marker", marker_texture(32), {"magFilter": LINEAR,
                                                       "minFilter": LINEAR_MIPMAP_LINEAR,
                                                       "wrapS": REPEAT, "wrapT": REPEAT})
        info = {"index": tex}
        if tt:
            info["extensions"] = {"KHR_texture_transform": tt}
        mat = g.material({"name": name, "pbrMetallicRoughness": {
            "baseColorTexture": info, "metallicFactor": 0.0, "roughnessFactor": 0.8}})
        g.node(g.mesh(quad(1.5, 1.5), mat, name), ((k % 3 - 1) * 1.75, (0.5 - k // 3) * 1.7, 0),
               name=name)
    return g.write((0.0, 0.0, 5.2), (0.0, 0.0, 0.0)), {}


def emissive_strength():
    mats = []
    for strength in (1.0, 3.0, 10.0):
        def make(g, strength=strength):
            g.use("KHR_materials_emissive_strength")
            return dict(name=f"emissive_x{strength:g}", emissiveFactor=[1.0, 0.4, 0.1],
                        extensions={"KHR_materials_emissive_strength": {
                            "emissiveStrength": strength}},
                        **pbr((0.05, 0.05, 0.05, 1.0), 0.0, 0.9))
        mats.append(make)
    mats.append(lambda g: dict(name="emissive_plain", emissiveFactor=[0.2, 0.6, 1.0],
                               **pbr((0.05, 0.05, 0.05, 1.0), 0.0, 0.9)))
    g = sphere_row("emissive_strength", mats)
    return g.write((0.0, 0.0, 3.9), (0.0, 0.0, 0.0)), {}


# ---- assimp sample wrappers -------------------------------------------------------------------

ASSIMP_MODELS = [
    # name, file under ASSIMP, view direction from the model's centre towards the camera
    ("BoxTextured", "BoxTextured-glTF/BoxTextured.gltf", (0.8, 0.6, 1.0)),
    ("BoxTexcoords", "BoxTexcoords-glTF/boxTexcoords.gltf", (0.8, 0.6, 1.0)),
    ("2CylinderEngine", "2CylinderEngine-glTF-Binary/2CylinderEngine.glb", (0.7, 0.5, 1.0)),
    ("ClearCoatTest", "ClearCoat-glTF/ClearCoatTest.gltf", (0.0, 0.0, 1.0)),
    ("TextureTransformTest", "textureTransform/TextureTransformTest.gltf", (0.0, 0.0, 1.0)),
    ("AnimatedMorphCube", "glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf",
     (0.8, 0.6, 1.0)),
]


def read_gltf_json(path):
    data = open(path, "rb").read()
    if data[:4] != b"glTF":
        return json.loads(data), None
    json_len = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + json_len])
    bin_start = 20 + json_len + 8  # the BIN chunk's data, after its length and type
    return doc, (bin_start, len(data))


def node_matrix(n):
    if "matrix" in n:
        return np.array(n["matrix"], np.float64).reshape(4, 4).T
    t = np.eye(4)
    t[:3, 3] = n.get("translation", [0, 0, 0])
    x, y, z, w = n.get("rotation", [0, 0, 0, 1])
    r = np.eye(4)
    r[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    s = np.diag(list(n.get("scale", [1, 1, 1])) + [1])
    return t @ r @ s


def scene_bounds(doc):
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    scene = doc["scenes"][doc.get("scene", 0)]

    def visit(i, parent):
        nonlocal lo, hi
        n = doc["nodes"][i]
        m = parent @ node_matrix(n)
        if "mesh" in n:
            for p in doc["meshes"][n["mesh"]]["primitives"]:
                acc = doc["accessors"][p["attributes"]["POSITION"]]
                a, b = acc["min"], acc["max"]
                for cx in (a[0], b[0]):
                    for cy in (a[1], b[1]):
                        for cz in (a[2], b[2]):
                            w = m @ np.array([cx, cy, cz, 1.0])
                            lo = np.minimum(lo, w[:3])
                            hi = np.maximum(hi, w[:3])
        for c in n.get("children", []):
            visit(c, m)

    for i in scene["nodes"]:
        visit(i, np.eye(4))
    return lo, hi


def fit_distance(lo, hi, centre, direction, radius, margin=0.08):
    """The nearest distance along `direction` from which the box's corners stay `margin` inside
    the frame (bisection between the box's radius and the bounding sphere's fit)."""
    corners = [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]

    def fits(d):
        eye = centre + direction * d
        for c in corners:
            x, y, z = project(eye, centre, c)
            if z <= 0 or not (margin <= x <= 1 - margin and margin <= y <= 1 - margin):
                return False
        return True

    near, far = radius * 1.01, radius / math.sin(YFOV / 2) * 1.5
    for _ in range(40):
        mid = (near + far) / 2
        near, far = (near, mid) if fits(mid) else (mid, far)
    return far


def assimp_wrapper(name, rel, direction):
    src = os.path.join(ASSIMP, rel)
    doc, glb = read_gltf_json(src)
    if glb:
        bin_start, size = glb
        doc["buffers"][0] = {"uri": os.path.basename(src), "byteLength": size}
        for v in doc["bufferViews"]:
            if v["buffer"] == 0:
                v["byteOffset"] = v.get("byteOffset", 0) + bin_start
    lo, hi = scene_bounds(doc)
    centre = (lo + hi) / 2
    radius = float(np.linalg.norm(hi - lo)) / 2
    dist = fit_distance(lo, hi, centre, normalize(direction), radius)
    eye = centre + normalize(direction) * dist
    cam_node, light_node, camera, light = view_nodes(eye, centre, round(dist * 0.02, 6),
                                                     round(dist * 4, 4))
    doc["cameras"] = doc.get("cameras", []) + [camera]
    cam_node["camera"] = len(doc["cameras"]) - 1
    doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {}).setdefault(
        "lights", [])
    lights = doc["extensions"]["KHR_lights_punctual"]["lights"]
    lights.append(light)
    light_node["extensions"]["KHR_lights_punctual"]["light"] = len(lights) - 1
    used = doc.setdefault("extensionsUsed", [])
    if "KHR_lights_punctual" not in used:
        used.append("KHR_lights_punctual")
    scene = doc["scenes"][doc.get("scene", 0)]
    for n in (cam_node, light_node):
        doc["nodes"].append(n)
        scene["nodes"].append(len(doc["nodes"]) - 1)
    doc["asset"]["generator"] = (doc["asset"].get("generator", "") +
                                 " + shadel tools/conformance/make_models.py wrapper")
    folder = os.path.join(MODELS, name)
    os.makedirs(folder, exist_ok=True)
    write_atomic(os.path.join(folder, f"{name}.gltf"), (json.dumps(doc, indent=1) + "\n").encode())
    return (f"tests/data/conformance/models/{name}/{name}.gltf",
            {"resources": os.path.dirname(src), "source": src})


def main():
    old = {}
    if os.path.exists(MANIFEST):
        manifest = json.load(open(MANIFEST))
        old = {m["name"]: m for m in manifest.get("models", [])}
    else:
        manifest = {}
    entries = []
    for make in (sphere_grid, alpha_modes, sampler_wrap, sampler_filter, double_sided, clearcoat,
                 sheen, transmission, texture_transform, emissive_strength):
        path, extra = make()
        entries.append((make.__name__, path, extra))
    for name, rel, direction in ASSIMP_MODELS:
        if not os.path.exists(os.path.join(ASSIMP, rel)):
            print("skipped (not installed):", rel)
            continue
        path, extra = assimp_wrapper(name, rel, direction)
        entries.append((name, path, extra))
    models = []
    for name, path, extra in entries:
        m = {"name": name, "file": path}
        m.update(extra)
        for key in ("floor_forward", "floor_decoupled", "note"):
            if key in old.get(name, {}):
                m[key] = old[name][key]
        models.append(m)
    manifest["models"] = models
    write_atomic(MANIFEST, (json.dumps(manifest, indent=2) + "\n").encode())
    print(f"wrote {len(models)} models into {MODELS} and {MANIFEST}")


if __name__ == "__main__":
    main()
