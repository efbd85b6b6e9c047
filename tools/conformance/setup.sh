#!/bin/sh
# Installs what the conformance harness needs, from Debian and npm only:
#   - Debian: chromium (the reference renderer's host; headless, WebGL through SwiftShader),
#     python3-numpy and python3-pil (compare.py).
#   - npm, into tools/conformance/node_modules (gitignored): the Khronos glTF Sample Viewer's
#     library and puppeteer-core to drive the Debian chromium. puppeteer-core 24.x runs on
#     Debian's node 20; 25.x needs node 22.
# Nothing is downloaded when the references are rendered. CI needs none of this: the reference
# images are committed under tests/data/conformance/reference/.
set -eu
here=$(cd "$(dirname "$0")" && pwd)

sudo_if_needed() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

sudo_if_needed apt-get install -y --no-install-recommends chromium python3-numpy python3-pil

cd "$here"
npm install --no-audit --no-fund --no-save --prefix "$here" \
    @khronosgroup/gltf-viewer@1.1.0 puppeteer-core@24.43.1
echo "setup: chromium $(/usr/lib/chromium/chromium --version 2>/dev/null || echo missing)"
