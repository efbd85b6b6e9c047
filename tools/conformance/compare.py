#!/usr/bin/python3
"""Compares shadel with the Khronos glTF Sample Viewer on the conformance models.

For every model of tools/conformance/models.json: renders it with shadel in forward and in
decoupled mode at the manifest's size (camera "conformance" and the file's light, the manifest's
environment, ACES Narkowicz, exposure 0 EV, no shadows, black background with alpha 0), reads
the reference tests/data/conformance/reference/NAME.png, and measures
  - PSNR (dB) of RGB over the covered pixels: where either image has alpha > 0;
  - for models with metal_regions (the sphere grid's metallic = 1 row): the mean absolute
    difference of CIE L* over those discs.
The reference encodes pow(linear, 1/2.2); it is decoded with that power and re-encoded with the
sRGB curve shadel writes, so both are compared in sRGB.

Writes docs/conformance/README.md (the table, the commit measured, the command) and
docs/conformance/NAME.png (reference | shadel forward | difference x4, and the decoupled pair
below). With --set-floors MARGIN, writes floor_forward / floor_decoupled = measured - MARGIN
(rounded down to 0.1 dB) into the manifest for the GPU test (tests/gpu/test_conformance.cpp);
with --floors-from LOG it takes the figures from that test's output instead (the test measures
over its own coverage, which a shadel PNG without alpha does not carry).

Usage: tools/conformance/compare.py [--shadel build/src/app/shadel] [--only NAME,...]
                                    [--set-floors 1.0] [--no-docs]
       tools/conformance/compare.py --floors-from GPU_TEST_LOG [--set-floors 1.0]
Needs python3-numpy and python3-pil (Debian); run with /usr/bin/python3.
"""
import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
MANIFEST = os.path.join(HERE, "models.json")
REFERENCE = os.path.join(ROOT, "tests", "data", "conformance", "reference")
DOCS = os.path.join(ROOT, "docs", "conformance")
MODES = ("forward", "decoupled")


def fail(message):
    print(f"compare.py: {message}", file=sys.stderr)
    sys.exit(2)


# ---- colour ----------------------------------------------------------------------------------

def srgb_encode(linear):
    linear = np.clip(linear, 0.0, 1.0)
    return np.where(linear <= 0.0031308, linear * 12.92, 1.055 * np.power(linear, 1 / 2.4) - 0.055)


def srgb_decode(encoded):
    return np.where(encoded <= 0.04045, encoded / 12.92, np.power((encoded + 0.055) / 1.055, 2.4))


def reference_as_srgb(rgba):
    """The viewer's pow(x, 1/2.2) RGB re-encoded with the sRGB curve, 0..255 floats."""
    linear = np.power(rgba[..., :3].astype(np.float64) / 255.0, 2.2)
    return np.round(srgb_encode(linear) * 255.0)


def shadel_over_black(rgba):
    """shadel's straight-alpha PNG composited over black as light (the reference's encoding of
    partly covered pixels), 0..255 sRGB floats; unchanged where alpha is 0 or 255."""
    a = rgba[..., 3:4].astype(np.float64) / 255.0
    linear = srgb_decode(rgba[..., :3].astype(np.float64) / 255.0) * np.where(a > 0, a, 1.0)
    return np.round(srgb_encode(linear) * 255.0)


def lightness(srgb255):
    """CIE L* of sRGB colours (0..255)."""
    lin = srgb_decode(srgb255 / 255.0)
    y = lin @ np.array([0.2126, 0.7152, 0.0722])
    f = np.where(y > (6 / 29) ** 3, np.cbrt(y), y / (3 * (6 / 29) ** 2) + 4 / 29)
    return 116 * f - 16


# ---- measures ----------------------------------------------------------------------------------

def covered_psnr(ref_rgb, ref_alpha, rgba):
    """PSNR of RGB over the union of both coverages; also the number of covered pixels."""
    covered = (ref_alpha > 0) | (rgba[..., 3] > 0)
    n = int(covered.sum())
    if n == 0:
        return float("nan"), 0
    diff = ref_rgb[covered] - rgba[..., :3][covered].astype(np.float64)
    mse = float(np.mean(diff * diff))
    return (99.0 if mse == 0 else 10 * math.log10(255.0 ** 2 / mse)), n


def region_mask(shape, regions):
    h, w = shape
    yy, xx = np.mgrid[0:h, 0:w]
    mask = np.zeros((h, w), bool)
    for cx, cy, r in regions:
        mask |= ((xx + 0.5) / w - cx) ** 2 * (w / h) ** 2 + ((yy + 0.5) / h - cy) ** 2 < r * r
    return mask


def metal_lightness_difference(ref_rgb, rgba, regions):
    mask = region_mask(ref_rgb.shape[:2], regions)
    if not mask.any():
        return float("nan")
    a = lightness(ref_rgb[mask])
    b = lightness(rgba[..., :3][mask].astype(np.float64))
    return float(np.mean(np.abs(a - b)))


# ---- shadel ------------------------------------------------------------------------------------

def supported_flags(shadel):
    try:
        text = subprocess.run([shadel, "render", "--help"], capture_output=True, text=True,
                              timeout=60).stdout
    except (OSError, subprocess.TimeoutExpired) as e:
        fail(f"{shadel}: cannot run ({e})")
    flags = ("--environment", "--environment-rotation", "--tonemap", "--exposure", "--background",
             "--sun", "--shadows", "--ssaa")
    return {f for f in flags if re.search(r"(?<![\w-])" + re.escape(f) + r"(?![\w-])", text)}


def stage(model, folder):
    """Links the model's folder's files and its resources folder's files into `folder`."""
    src = os.path.join(ROOT, os.path.dirname(model["file"]))
    os.makedirs(folder, exist_ok=True)
    for directory in filter(None, (model.get("resources"), src)):
        for f in os.listdir(directory):
            dst = os.path.join(folder, f)
            if os.path.lexists(dst):
                os.remove(dst)
            os.symlink(os.path.join(directory, f), dst)
    return os.path.join(folder, os.path.basename(model["file"]))


def shadel_flags(manifest, supported):
    """The view's flags, and the ones this build lacks."""
    wanted = [
        ("--environment", os.path.join(ROOT, manifest["environment"])),
        ("--environment-rotation", str(manifest["shadel_environment_rotation"])),
        ("--tonemap", manifest["tonemap"]),
        ("--background", ",".join(str(c) for c in manifest["background"])),
        ("--sun", "off"),
        ("--shadows", "off"),
        ("--ssaa", str(manifest.get("shadel_ssaa", 1))),
    ]
    if manifest["exposure_ev"] != 0:  # 0 EV is shadel's default
        wanted.append(("--exposure", str(manifest["exposure_ev"])))
    flags, missing = [], []
    for flag, value in wanted:
        if flag in supported:
            flags += [flag, value]
        else:
            missing.append(flag)
    return flags, missing


def render(shadel, scene, mode, size, flags, out):
    cmd = [shadel, "render", "--scene", scene, "--camera", "conformance", "--mode", mode,
           "--size", f"{size[0]}x{size[1]}", "--out", out, "--allow-external-files"] + flags
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {r.returncode}: {r.stderr.strip()[-400:]}")
    img = Image.open(out)
    has_alpha = img.mode in ("RGBA", "LA")
    return np.array(img.convert("RGBA")), has_alpha


# ---- pictures ----------------------------------------------------------------------------------

def side_by_side(ref_rgb, ref_alpha, renders):
    """Rows of reference | shadel | difference x4 (over the covered pixels PSNR measures)."""
    rows = []
    for rgba in renders:
        shadel_rgb = rgba[..., :3].astype(np.float64)
        covered = (ref_alpha > 0) | (rgba[..., 3] > 0)
        diff = np.clip(np.abs(ref_rgb - shadel_rgb) * 4, 0, 255) * covered[..., None]
        rows.append(np.concatenate([ref_rgb, shadel_rgb, diff], axis=1))
    img = np.concatenate(rows, axis=0).astype(np.uint8)
    return Image.fromarray(img, "RGB")


def git_commit():
    r = subprocess.run(["git", "-C", ROOT, "log", "-1", "--format=%h %s"], capture_output=True,
                       text=True)
    return r.stdout.strip()[:100] if r.returncode == 0 else "unknown"


def save_png(img, path):
    tmp = path + ".tmp.png"
    img.save(tmp, optimize=True)
    os.replace(tmp, path)


def write_docs(results, manifest, missing, notes, commit, command, seconds):
    lines = ["# Conformance with the Khronos glTF Sample Viewer", "",
             "shadel against the reference implementation of glTF PBR, the Khronos glTF Sample",
             "Viewer (tests/data/conformance/reference/, versions in VERSIONS.md there), on the",
             "models of tools/conformance/models.json: generated scenes (tools/conformance/"
             "make_models.py)",
             "and wrappers of the assimp glTF2 sample models. How the harness works:",
             "tools/conformance/README.md.", "",
             f"Measured on `{commit}` with `{command}` ({seconds:.0f} s), "
             f"{manifest['size'][0]}x{manifest['size'][1]}: the reference drawn "
             f"{manifest.get('reference_scale', 1)}x as large "
             f"({'multisampled' if manifest.get('reference_msaa') else 'one sample per pixel'}) "
             f"and box-filtered, "
             f"shadel with --ssaa {manifest.get('shadel_ssaa', 1)}.", "",
             "PSNR is over covered pixels (alpha > 0 in either image), RGB in sRGB encoding;",
             "the images (docs/conformance/NAME.png) are reference | shadel | difference x4,",
             "forward above, decoupled below. The GPU test's own figures and floors:",
             "[gpu_test.md](gpu_test.md).", ""]
    if missing:
        lines += [f"This build lacked {', '.join(missing)}: those parts of the view were shadel's "
                  "defaults, so these figures do not yet measure conformance.", ""]
    lines += [f"Note: {n}." for n in notes] + ([""] if notes else [])
    lines += ["| model | forward PSNR (dB) | decoupled PSNR (dB) | covered pixels | metal L* diff "
              "(fwd / dec) |", "| --- | --- | --- | --- | --- |"]
    for r in results:
        lstar = "" if "lstar_forward" not in r else \
            f"{r['lstar_forward']:.2f} / {r['lstar_decoupled']:.2f}"
        pf = f"{r['psnr_forward']:.2f}" if "psnr_forward" in r else r.get("error", "failed")
        pd = f"{r['psnr_decoupled']:.2f}" if "psnr_decoupled" in r else ""
        lines.append(f"| [{r['name']}]({r['name']}.png) | {pf} | {pd} | {r.get('covered', '')} "
                     f"| {lstar} |")
    lines.append("")
    os.makedirs(DOCS, exist_ok=True)
    path = os.path.join(DOCS, "README.md")
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(lines))
    os.replace(path + ".tmp", path)


def write_manifest(manifest):
    with open(MANIFEST + ".tmp", "w") as f:
        f.write(json.dumps(manifest, indent=2) + "\n")
    os.replace(MANIFEST + ".tmp", MANIFEST)


def floors_from_log(log, margin):
    """Floors = the figures the GPU test printed ("[ figures ] conformance NAME MODE: PSNR X dB")
    minus `margin`, rounded down to 0.1 dB."""
    measured = {}
    with open(log) as f:
        for line in f:
            m = re.search(r"\[ figures \] conformance (\S+) (forward|decoupled): PSNR ([\d.]+) dB",
                          line)
            if m:
                measured[(m.group(1), m.group(2))] = float(m.group(3))
    if not measured:
        fail(f"{log}: no conformance figures in it")
    with open(MANIFEST) as f:
        manifest = json.load(f)
    for model in manifest["models"]:
        for mode in MODES:
            if (model["name"], mode) in measured:
                p = measured[(model["name"], mode)]
                model[f"floor_{mode}"] = math.floor((p - margin) * 10) / 10
    write_manifest(manifest)
    lines = ["# GPU test figures (Models/Conformance)", "",
             "PSNR of shadel against the glTF Sample Viewer as tests/gpu/test_conformance.cpp "
             "measures it",
             "(over the pixels either image covers, shadel's coverage from the renderer) and the "
             f"floors set from them ({margin:g} dB below, rounded down to 0.1 dB), on "
             f"`{git_commit()}`.", "",
             "| model | forward (dB) | floor | decoupled (dB) | floor |",
             "| --- | --- | --- | --- | --- |"]
    for model in manifest["models"]:
        cells = []
        for mode in MODES:
            p = measured.get((model["name"], mode))
            cells += [f"{p:.2f}" if p is not None else "", str(model.get(f"floor_{mode}", ""))]
        lines.append(f"| {model['name']} | " + " | ".join(cells) + " |")
    os.makedirs(DOCS, exist_ok=True)
    path = os.path.join(DOCS, "gpu_test.md")
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(path + ".tmp", path)
    print(f"set {len(measured)} floors from {log}; wrote {path}")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--shadel", default=os.path.join(ROOT, "build", "src", "app", "shadel"))
    ap.add_argument("--only", default="")
    ap.add_argument("--set-floors", type=float, default=None, metavar="MARGIN_DB")
    ap.add_argument("--no-docs", action="store_true")
    ap.add_argument("--keep", metavar="DIR", help="render into DIR and keep the renders")
    ap.add_argument("--floors-from", metavar="LOG",
                    help="set the floors from a GPU test log's figures (Models/Conformance.*) "
                         "minus --set-floors (default 1.0 dB), render nothing")
    args = ap.parse_args()
    if args.floors_from:
        return floors_from_log(args.floors_from, 1.0 if args.set_floors is None else args.set_floors)
    if not os.access(args.shadel, os.X_OK):
        fail(f"{args.shadel}: not an executable (build shadel first)")
    with open(MANIFEST) as f:
        manifest = json.load(f)
    only = set(filter(None, args.only.split(",")))
    models = [m for m in manifest["models"] if not only or m["name"] in only]
    supported = supported_flags(args.shadel)
    flags, missing = shadel_flags(manifest, supported)
    if missing:
        print(f"compare.py: this shadel lacks {', '.join(missing)}; rendering without them")
    size = manifest["size"]
    started = time.time()
    results = []
    notes = set()
    tmp = args.keep or tempfile.mkdtemp(prefix="shadel_conformance_")
    os.makedirs(tmp, exist_ok=True)
    try:
        for m in models:
            name = m["name"]
            r = {"name": name}
            ref_path = os.path.join(REFERENCE, f"{name}.png")
            if not os.path.exists(ref_path):
                r["error"] = "no reference"
                results.append(r)
                print(f"{name}: no reference {ref_path}")
                continue
            ref = np.array(Image.open(ref_path).convert("RGBA"))
            ref_rgb = reference_as_srgb(ref)
            scene = stage(m, os.path.join(tmp, name))
            renders = []
            try:
                for mode in MODES:
                    out = os.path.join(tmp, f"{name}_{mode}.png")
                    rgba, has_alpha = render(args.shadel, scene, mode, size, flags, out)
                    if rgba.shape != ref.shape:
                        raise RuntimeError(f"size {rgba.shape} differs from the reference's")
                    if not has_alpha:  # no coverage in the file: the reference's alone counts
                        rgba[..., 3] = 0
                        notes.add("shadel's PNG had no alpha: PSNR over the reference's coverage")
                    rgba[..., :3] = shadel_over_black(rgba)
                    p, n = covered_psnr(ref_rgb, ref[..., 3], rgba)
                    r[f"psnr_{mode}"] = p
                    r["covered"] = n
                    if m.get("metal_regions"):
                        r[f"lstar_{mode}"] = metal_lightness_difference(ref_rgb, rgba,
                                                                        m["metal_regions"])
                    renders.append(rgba)
            except RuntimeError as e:
                r["error"] = "render failed"
                print(f"{name}: {e}")
            results.append(r)
            if len(renders) == len(MODES) and not args.no_docs:
                os.makedirs(DOCS, exist_ok=True)
                save_png(side_by_side(ref_rgb, ref[..., 3], renders), os.path.join(DOCS, f"{name}.png"))
            print(f"{name}: forward {r.get('psnr_forward', float('nan')):.2f} dB, decoupled "
                  f"{r.get('psnr_decoupled', float('nan')):.2f} dB"
                  + (f", metal L* diff {r['lstar_forward']:.2f} / {r['lstar_decoupled']:.2f}"
                     if "lstar_forward" in r else ""), flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(tmp, ignore_errors=True)
    seconds = time.time() - started
    command = "tools/conformance/compare.py" + (f" --only {args.only}" if args.only else "")
    if not args.no_docs:
        write_docs(results, manifest, missing, sorted(notes), git_commit(), command, seconds)
    if args.set_floors is not None:
        by_name = {r["name"]: r for r in results}
        for m in manifest["models"]:
            r = by_name.get(m["name"])
            for mode in MODES:
                if r and f"psnr_{mode}" in r:
                    m[f"floor_{mode}"] = math.floor((r[f"psnr_{mode}"] - args.set_floors) * 10) / 10
        write_manifest(manifest)
    return 0


if __name__ == "__main__":
    sys.exit(main())
