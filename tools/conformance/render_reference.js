#!/usr/bin/env node
// Renders every model of tools/conformance/models.json with the Khronos glTF Sample Viewer
// (@khronosgroup/gltf-viewer) in headless Debian chromium (WebGL2 through SwiftShader) and
// writes tests/data/conformance/reference/NAME.png plus VERSIONS.md.
//
// All models render in one page: the viewer prefilters the environment once per page (minutes
// under SwiftShader), then each model takes seconds. The page's files are served from this
// machine by request interception (nothing is fetched from the network):
//   /viewer/...       the viewer's dist folder (its WASM helpers under /viewer/libs/)
//   /environment.hdr  the manifest's environment; /lut_sheen_E.png the sheen albedo table
//   /models/NAME/F    F from the model's committed folder, else from its "resources" folder
//
// The view: the file's camera named "conformance" (state.cameraIndex) and its lights
// (usePunctual), the environment as image-based light (useIBL, iblIntensity 1) but not drawn
// (renderEnvironmentMap false), clearColor (0, 0, 0, 0), exposure 1, tone map "ACES Filmic Tone
// Mapping (Narkowicz)", no animation. The PNG holds the drawing buffer as read back: RGB as the
// viewer encodes it, pow(x, 1/2.2) (not the sRGB curve), over black; alpha is coverage (0 where
// nothing was drawn). The canvas is reference_scale times the size, one sample per canvas pixel
// unless reference_msaa, and box-filtered down (see README.md). The camera's aspectRatio is left
// to the canvas: the viewer sizes its viewport by the file's aspect ratio, and a ratio written
// a hair above the canvas's (1.7777778 for 16:9) truncates the viewport to one row fewer.
//
// Usage: node tools/conformance/render_reference.js [--only NAME[,NAME...]] [--chromium PATH]
//          [--out DIR] [--scale N] [--msaa | --no-msaa] [--no-punctual] [--no-ibl]
// --scale and --msaa default to the manifest's reference_scale and reference_msaa; --out
// (experiments) writes elsewhere and leaves VERSIONS.md alone. CONFORMANCE_ENVIRONMENT=FILE.hdr
// replaces the manifest's environment (a small one skips minutes of prefiltering).
"use strict";
const fs = require("fs");
const path = require("path");
const zlib = require("zlib");
const { execFileSync } = require("child_process");
const puppeteer = require("puppeteer-core");

const here = __dirname;
const root = path.resolve(here, "..", "..");
const viewerDir = path.join(here, "node_modules", "@khronosgroup", "gltf-viewer");
const outDir = path.join(root, "tests", "data", "conformance", "reference");
const origin = "http://conformance.invalid";

function parseArgs() {
  const args = { only: null, chromium: "/usr/lib/chromium/chromium", out: null, msaa: null,
    scale: null, punctual: true, ibl: true };
  const argv = process.argv.slice(2);
  for (let i = 0; i < argv.length; i++) {
    if (argv[i] === "--only") args.only = argv[++i].split(",");
    else if (argv[i] === "--chromium") args.chromium = argv[++i];
    else if (argv[i] === "--out") args.out = argv[++i];
    else if (argv[i] === "--msaa") args.msaa = true;
    else if (argv[i] === "--no-msaa") args.msaa = false;
    else if (argv[i] === "--no-punctual") args.punctual = false;
    else if (argv[i] === "--no-ibl") args.ibl = false;
    else if (argv[i] === "--scale") args.scale = Number(argv[++i]);
    else {
      console.error(`render_reference.js: unknown argument ${argv[i]}`);
      process.exit(2);
    }
  }
  return args;
}

// ---- PNG writing (RGBA 8-bit) ------------------------------------------------------------

const crcTable = (() => {
  const t = new Uint32Array(256);
  for (let n = 0; n < 256; n++) {
    let c = n;
    for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    t[n] = c >>> 0;
  }
  return t;
})();

function crc32(buf) {
  let c = 0xffffffff;
  for (const b of buf) c = crcTable[(c ^ b) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}

function chunk(type, data) {
  const len = Buffer.alloc(4);
  len.writeUInt32BE(data.length);
  const td = Buffer.concat([Buffer.from(type, "ascii"), data]);
  const crc = Buffer.alloc(4);
  crc.writeUInt32BE(crc32(td));
  return Buffer.concat([len, td, crc]);
}

function encodePng(width, height, rgba) {
  const ihdr = Buffer.alloc(13);
  ihdr.writeUInt32BE(width, 0);
  ihdr.writeUInt32BE(height, 4);
  ihdr[8] = 8; // bit depth
  ihdr[9] = 6; // RGBA
  const raw = Buffer.alloc((width * 4 + 1) * height);
  for (let y = 0; y < height; y++) {
    raw[y * (width * 4 + 1)] = 0; // filter: none
    rgba.copy(raw, y * (width * 4 + 1) + 1, y * width * 4, (y + 1) * width * 4);
  }
  return Buffer.concat([
    Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]),
    chunk("IHDR", ihdr),
    chunk("IDAT", zlib.deflateSync(raw, { level: 9 })),
    chunk("IEND", Buffer.alloc(0)),
  ]);
}

// Box-filters a (width*scale) x (height*scale) readback to width x height: RGB averaged as light
// (the viewer's pow(x, 1/2.2) undone, then redone), alpha averaged as coverage.
function downsample(rgba, width, height, scale) {
  if (scale === 1) return rgba;
  const out = Buffer.alloc(width * height * 4);
  const w = width * scale;
  const n = scale * scale;
  for (let y = 0; y < height; y++) {
    for (let x = 0; x < width; x++) {
      const sum = [0, 0, 0, 0];
      for (let sy = 0; sy < scale; sy++) {
        for (let sx = 0; sx < scale; sx++) {
          const i = ((y * scale + sy) * w + x * scale + sx) * 4;
          for (let c = 0; c < 3; c++) sum[c] += Math.pow(rgba[i + c] / 255, 2.2);
          sum[3] += rgba[i + 3];
        }
      }
      const o = (y * width + x) * 4;
      for (let c = 0; c < 3; c++) out[o + c] = Math.round(Math.pow(sum[c] / n, 1 / 2.2) * 255);
      out[o + 3] = Math.round(sum[3] / n);
    }
  }
  return out;
}

function writeAtomic(file, data) {
  const tmp = `${file}.tmp`;
  fs.writeFileSync(tmp, data);
  fs.renameSync(tmp, file);
}

// ---- serving the page's files ------------------------------------------------------------

const mimeTypes = {
  ".js": "text/javascript", ".wasm": "application/wasm", ".png": "image/png",
  ".jpg": "image/jpeg", ".jpeg": "image/jpeg", ".gltf": "model/gltf+json",
  ".glb": "model/gltf-binary", ".bin": "application/octet-stream", ".hdr": "image/vnd.radiance",
  ".html": "text/html",
};

function pageHtml() {
  return `<!doctype html><html><body style="margin:0;background:#000">
<script type="module">
import * as viewer from "/viewer/dist/gltf-viewer.module.js";
window.viewerModule = viewer;
window.viewerReady = true;
</script></body></html>`;
}

function resolveFile(manifest, urlPath) {
  const p = decodeURIComponent(urlPath);
  if (p === "/favicon.ico") return { body: Buffer.alloc(0), type: "image/x-icon" };
  if (p === "/index.html") return { body: Buffer.from(pageHtml()), type: "text/html" };
  let file = null;
  if (p.startsWith("/viewer/")) file = path.join(viewerDir, p.slice("/viewer/".length));
  else if (p === "/environment.hdr") file = process.env.CONFORMANCE_ENVIRONMENT || path.join(root, manifest.environment);
  else if (p === "/lut_sheen_E.png") file = path.join(here, "lut_sheen_E.png");
  else if (p.startsWith("/models/")) {
    const [name, ...rest] = p.slice("/models/".length).split("/");
    const model = manifest.models.find((m) => m.name === name);
    if (model) {
      const rel = rest.join("/");
      const own = path.join(root, path.dirname(model.file), rel);
      file = fs.existsSync(own) || !model.resources ? own : path.join(model.resources, rel);
    }
  }
  if (!file || !fs.existsSync(file)) return null;
  return { body: fs.readFileSync(file), type: mimeTypes[path.extname(file).toLowerCase()] };
}

// ---- in the page -------------------------------------------------------------------------

async function setUpViewer(page, settings) {
  return page.evaluate(async (settings) => {
    const { GltfView, GltfState, ResourceLoader } = window.viewerModule;
    const canvas = document.createElement("canvas");
    canvas.width = settings.width;
    canvas.height = settings.height;
    document.body.appendChild(canvas);
    const gl = canvas.getContext("webgl2", {
      alpha: true, antialias: settings.msaa, premultipliedAlpha: false, preserveDrawingBuffer: true,
    });
    const view = new GltfView(gl);
    const state = view.createState();
    // No model needs KTX2 or Draco: the loader is made without their decoders.
    const loader = new ResourceLoader(view, "/viewer/dist/libs/");
    const p = state.renderingParameters;
    p.toneMap = GltfState.ToneMaps.ACES_NARKOWICZ;
    p.exposure = 1.0;
    p.usePunctual = settings.punctual;
    p.useIBL = settings.ibl;
    p.iblIntensity = 1.0;
    p.renderEnvironmentMap = false;
    p.clearColor = [0, 0, 0, 0];
    p.environmentRotation = settings.environmentRotation;
    state.animationIndices = [];
    // The prefiltering is queued here and runs when the first model is drawn: its time shows
    // in the first model's.
    state.environment = await loader.loadEnvironment("/environment.hdr", {
      lut_sheen_E_file: "/lut_sheen_E.png",
    });
    window.conformance = { gl, view, state, loader, canvas };
    return {
      renderer: gl.getParameter(gl.getExtension("WEBGL_debug_renderer_info").UNMASKED_RENDERER_WEBGL),
      userAgent: navigator.userAgent,
    };
  }, settings);
}

async function renderModel(page, name, file) {
  return page.evaluate(async (name, url) => {
    const { gl, view, state, loader, canvas } = window.conformance;
    const t0 = performance.now();
    state.gltf = await loader.loadGltf(url);
    state.sceneIndex = state.gltf.scene !== undefined ? state.gltf.scene : 0;
    const cameras = state.gltf.cameras || [];
    state.cameraIndex = cameras.findIndex((c) => c.name === "conformance");
    if (state.cameraIndex < 0) throw new Error(`${name}: no camera named "conformance"`);
    const perspective = cameras[state.cameraIndex].perspective;
    if (perspective && perspective.aspectRatio !== undefined) {
      const canvasAspect = canvas.width / canvas.height;
      if (Math.abs(perspective.aspectRatio - canvasAspect) > 1e-4 * canvasAspect)
        throw new Error(`${name}: camera aspect ratio ${perspective.aspectRatio} is not the canvas's ${canvasAspect}`);
      perspective.aspectRatio = undefined; // the canvas's exactly (see the header)
    }
    for (let i = 0; i < 3; i++) view.renderFrame(state, canvas.width, canvas.height);
    gl.finish();
    const w = canvas.width, h = canvas.height;
    const px = new Uint8Array(w * h * 4);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    // readPixels returns the bottom row first; the PNG wants the top row first.
    const rows = new Uint8Array(w * h * 4);
    for (let y = 0; y < h; y++) rows.set(px.subarray((h - 1 - y) * w * 4, (h - y) * w * 4), y * w * 4);
    let s = "";
    for (let i = 0; i < rows.length; i += 0x8000) s += String.fromCharCode.apply(null, rows.subarray(i, i + 0x8000));
    return { rgba: btoa(s), seconds: (performance.now() - t0) / 1000 };
  }, name, file);
}

// ---- main --------------------------------------------------------------------------------

function versions(chromium) {
  const pkg = (p) => JSON.parse(fs.readFileSync(path.join(here, "node_modules", p, "package.json"))).version;
  let chromiumVersion = "unknown";
  try {
    chromiumVersion = execFileSync(chromium, ["--version"]).toString().trim();
  } catch (e) { /* recorded as unknown */ }
  let debian = "";
  try {
    debian = execFileSync("dpkg-query", ["-W", "-f=${Version}", "chromium"]).toString().trim();
  } catch (e) { /* not a Debian package */ }
  return {
    chromium: chromiumVersion + (debian ? ` (Debian package chromium ${debian})` : ""),
    viewer: pkg("@khronosgroup/gltf-viewer"),
    puppeteer: pkg("puppeteer-core"),
    node: process.version,
  };
}

async function main() {
  const args = parseArgs();
  const manifest = JSON.parse(fs.readFileSync(path.join(here, "models.json")));
  const [width, height] = manifest.size;
  const models = manifest.models.filter((m) => !args.only || args.only.includes(m.name));
  fs.mkdirSync(outDir, { recursive: true });
  const started = Date.now();
  const browser = await puppeteer.launch({
    executablePath: args.chromium,
    headless: true,
    protocolTimeout: 30 * 60 * 1000,
    args: ["--headless", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
      "--no-sandbox", "--ignore-gpu-blocklist", "--disable-gpu-sandbox"],
  });
  try {
    const page = await browser.newPage();
    page.setDefaultTimeout(30 * 60 * 1000);
    page.on("console", (m) => console.log(`[page] ${m.text()}`));
    page.on("pageerror", (e) => console.log(`[page error] ${e.message}`));
    await page.setRequestInterception(true);
    page.on("request", (req) => {
      const url = new URL(req.url());
      const found = url.origin === origin ? resolveFile(manifest, url.pathname) : null;
      if (!found) {
        console.log(`[serve] not found: ${req.url()}`);
        req.respond({ status: 404, body: "" });
        return;
      }
      req.respond({ status: 200, contentType: found.type, body: found.body });
    });
    const scale = args.scale || manifest.reference_scale || 1;
    const msaa = args.msaa !== null ? args.msaa : manifest.reference_msaa === true;
    const out = args.out || outDir;
    fs.mkdirSync(out, { recursive: true });
    await page.setViewport({ width: width * scale, height: height * scale });
    await page.goto(`${origin}/index.html`);
    await page.waitForFunction(() => window.viewerReady === true);
    const env = await setUpViewer(page, {
      width: width * scale, height: height * scale, msaa,
      punctual: args.punctual, ibl: args.ibl,
      environmentRotation: manifest.viewer_environment_rotation,
    });
    console.log(`WebGL renderer: ${env.renderer}`);
    const timings = [];
    for (const m of models) {
      const url = `/models/${m.name}/${path.basename(m.file)}`;
      const r = await renderModel(page, m.name, url);
      const rgba = downsample(Buffer.from(r.rgba, "base64"), width, height, scale);
      writeAtomic(path.join(out, `${m.name}.png`), encodePng(width, height, rgba));
      timings.push(`${m.name} ${r.seconds.toFixed(1)} s`);
      console.log(`${m.name}: ${r.seconds.toFixed(1)} s`);
    }
    const total = (Date.now() - started) / 1000;
    const v = versions(args.chromium);
    const command = `node tools/conformance/render_reference.js${args.only ? " --only " + args.only.join(",") : ""}`;
    const md = `# Reference images: versions and command

Rendered by the Khronos glTF Sample Viewer for tools/conformance/compare.py and
tests/gpu/test_conformance.cpp. Regenerate with \`tools/conformance/setup.sh\` (once), then
\`${command}\` from the repository root.

| what | version |
| --- | --- |
| chromium | ${v.chromium} |
| WebGL renderer | ${env.renderer} |
| @khronosgroup/gltf-viewer | ${v.viewer} |
| puppeteer-core | ${v.puppeteer} |
| node | ${v.node} |

- Chromium flags: \`--headless --use-angle=swiftshader --enable-unsafe-swiftshader --no-sandbox\`.
- Size ${width}x${height}: drawn ${scale}x as large into a canvas with ${msaa ? "multisampling" : "one sample per pixel"},
  the camera's aspect ratio taken from the canvas (see render_reference.js), then
  box-filtered (RGB as light, alpha as coverage); camera "conformance" and the file's lights; environment
  ${manifest.environment} as image-based light only (not drawn), environmentRotation
  ${manifest.viewer_environment_rotation}; tone map ACES Filmic (Narkowicz), exposure 1;
  clear colour (0, 0, 0, 0).
- Encoding: RGB is the viewer's output, pow(linear, 1/2.2) — not the sRGB curve — over black;
  alpha is coverage. Comparisons decode with the 2.2 power and re-encode with the sRGB curve.
- The sheen albedo table (lut_sheen_E.png) is computed by tools/conformance/make_environment.py;
  the viewer's npm package does not ship it.
- The whole run took ${total.toFixed(0)} s. The viewer prefilters the environment when the first
  model is drawn, so the first model's time includes it (${models.length} models: ${timings.join(", ")}).
`;
    if (!args.only && !args.out) writeAtomic(path.join(outDir, "VERSIONS.md"), md);
    console.log(`done in ${total.toFixed(0)} s`);
  } finally {
    await browser.close();
  }
}

main().catch((e) => {
  console.error(`render_reference.js: ${e.message}`);
  process.exit(1);
});
