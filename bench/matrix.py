#!/usr/bin/python3
"""The decoupled-shading payoff matrix: `shadel bench` (forward, decoupled, reuse; interleaved
rounds, ratios as medians of the rounds') for every scene x size x camera path, gathered into one
JSON, a Markdown table and a bar chart.

Usage (from the repository root, after scripts/build.sh):
    /usr/bin/python3 bench/matrix.py [--scenes builtin:default,builtin:many,...]
        [--sizes 960x540,1280x720,1920x1080] [--paths orbit,walk] [--frames N] [--rounds N]
        [--out bench/results/matrix] [--shadel build/src/app/shadel]

Writes OUT.json (every cell's ratios, median frame times and the reuse frame's pass table),
OUT.md (the table) and OUT.png (ratios per cell), each atomically. Prints a line per cell as it
finishes; a cell that fails is recorded with its error and the run goes on.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

# Passes whose cost follows the pixel count in a decoupled frame: the visibility (or depth)
# prepass, marking and the resolve (or the raster reconstruction).
PIXEL_PASSES = ("visibilityPrepass", "markingCompute", "markingRaster", "resolveCompute",
                "reconstruction")

DEFAULT_SCENES = ("builtin:default,builtin:many,builtin:lights,"
                  "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb")


def write_atomic(path, data):
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".matrix-", dir=folder)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def pass_ms(mode):
    return {p["name"]: p["gpu_ms"] for p in mode.get("passes", [])}


def run_cell(args, scene, size, path, tmp):
    out = os.path.join(tmp, "cell.json")
    cmd = [args.shadel, "bench", "--scene", scene, "--size", size, "--camera-path", path,
           "--frames", str(args.frames), "--rounds", str(args.rounds), "--json", out]
    started = time.time()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    seconds = time.time() - started
    cell = {"scene": scene, "size": size, "path": path, "seconds": round(seconds, 1),
            "command": " ".join(cmd[1:-2])}
    if proc.returncode != 0:
        lines = (proc.stderr or proc.stdout).strip().splitlines()
        cell["error"] = lines[-1] if lines else f"exit {proc.returncode}"
        return cell
    with open(out) as f:
        bench = json.load(f)
    modes = bench["modes"]
    forward_ms = modes["forward"]["frame_ms"]["median"]
    reuse_passes = pass_ms(modes["reuse"])
    pixel_ms = sum(reuse_passes.get(p, 0.0) for p in PIXEL_PASSES)
    cell.update({
        "ratios": bench["ratios"],
        "ratios_by_round": bench["ratios_by_round"],
        "frame_ms": {m: modes[m]["frame_ms"]["median"] for m in modes},
        "reuse_fraction": modes["reuse"].get("reuse_fraction"),
        "pixel_passes_ms": round(pixel_ms, 3),
        "pixel_passes_over_forward": round(pixel_ms / forward_ms, 4) if forward_ms > 0 else None,
        "reuse_passes_ms": reuse_passes,
        "host": bench.get("host"),
        "device": bench.get("device"),
    })
    return cell


def short(scene):
    return scene if scene.startswith("builtin:") else os.path.basename(scene)


def table(cells):
    rows = ["| scene | size | path | forward ms | decoupled | reuse | reuse fraction | "
            "pixel passes / forward |", "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for c in cells:
        if "error" in c:
            rows.append(f"| {short(c['scene'])} | {c['size']} | {c['path']} | failed: {c['error']} "
                        "| | | | |")
            continue
        r = c["ratios"]
        rows.append(f"| {short(c['scene'])} | {c['size']} | {c['path']} | "
                    f"{c['frame_ms']['forward']:.1f} | {r['decoupled']:.3f} | {r['reuse']:.3f} | "
                    f"{c['reuse_fraction']:.3f} | {c['pixel_passes_over_forward']:.3f} |")
    return "\n".join(rows) + "\n"


def plot(cells, path):
    """Two bars per cell (decoupled, reuse: frame time over forward's), the 1.0 line and the
    0.5 goal; PIL only (no plotting library on the host)."""
    from PIL import Image, ImageDraw
    ok = [c for c in cells if "error" not in c]
    bar, gap, left, top, height = 10, 8, 60, 20, 260
    width = max(420, left + max(1, len(ok)) * (2 * bar + gap) + 20)
    img = Image.new("RGB", (width, top + height + 150), "white")
    d = ImageDraw.Draw(img)
    scale = height / 1.5  # ratio 1.5 at the top

    def y(ratio):
        return top + height - min(ratio, 1.5) * scale

    for ratio, colour in ((1.0, (120, 120, 120)), (0.5, (60, 160, 60))):
        d.line([(left, y(ratio)), (width - 10, y(ratio))], fill=colour)
        d.text((5, y(ratio) - 6), f"{ratio:.1f}", fill=colour)
    for i, c in enumerate(ok):
        x = left + i * (2 * bar + gap)
        for j, (key, colour) in enumerate((("decoupled", (70, 110, 200)),
                                           ("reuse", (230, 140, 40)))):
            x0 = x + j * bar
            d.rectangle([x0, y(c["ratios"][key]), x0 + bar - 2, top + height], fill=colour)
        label = f"{short(c['scene']).replace('builtin:', '')[:10]} {c['size']} {c['path']}"
        for k, ch in enumerate(label[:28]):
            d.text((x + 2, top + height + 4 + 9 * k), ch, fill="black")
    d.text((left, 2), "frame time / forward: decoupled (blue), reuse (orange)", fill="black")
    from io import BytesIO
    buf = BytesIO()
    img.save(buf, format="PNG")
    write_atomic(path, buf.getvalue())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--shadel", default="build/src/app/shadel")
    ap.add_argument("--scenes", default=DEFAULT_SCENES)
    ap.add_argument("--sizes", default="960x540,1280x720,1920x1080")
    ap.add_argument("--paths", default="orbit,walk")
    ap.add_argument("--frames", type=int, default=12)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--out", default="bench/results/matrix")
    args = ap.parse_args()
    if not os.access(args.shadel, os.X_OK):
        sys.exit(f"matrix.py: {args.shadel}: not an executable (run scripts/build.sh first)")
    if args.frames < 2 or args.rounds < 1:
        sys.exit("matrix.py: --frames must be at least 2 and --rounds at least 1")
    grid = [(s, z, p) for s in args.scenes.split(",") for z in args.sizes.split(",")
            for p in args.paths.split(",")]
    cells = []
    started = time.time()
    with tempfile.TemporaryDirectory(prefix="shadel_matrix_") as tmp:
        for n, (scene, size, path) in enumerate(grid, 1):
            print(f"[{n}/{len(grid)}] {scene} {size} {path} ...", end="", flush=True)
            cell = run_cell(args, scene, size, path, tmp)
            cells.append(cell)
            if "error" in cell:
                print(f" failed ({cell['seconds']:.0f} s): {cell['error']}", flush=True)
            else:
                r = cell["ratios"]
                print(f" decoupled {r['decoupled']:.3f}, reuse {r['reuse']:.3f}, pixel passes "
                      f"{cell['pixel_passes_over_forward']:.3f} of forward "
                      f"({cell['seconds']:.0f} s)", flush=True)
            # Written after every cell, so an interrupted run keeps what it measured.
            result = {"schema": 1, "frames": args.frames, "rounds": args.rounds,
                      "seconds": round(time.time() - started, 1), "cells": cells}
            write_atomic(args.out + ".json", (json.dumps(result, indent=1) + "\n").encode())
    write_atomic(args.out + ".md", table(cells).encode())
    plot(cells, args.out + ".png")
    failed = sum("error" in c for c in cells)
    print(f"matrix: {len(cells)} cells ({failed} failed) in {time.time() - started:.0f} s -> "
          f"{args.out}.json, .md, .png")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
