#!/usr/bin/env bash
# Installs everything shadel needs on Debian 12 (or newer) from Debian packages.
# Lavapipe must be Mesa >= 24: on bookworm that is bookworm-backports, added by reusing the
# mirror URI the system's own apt sources already use (no mirror host is written here).
set -euo pipefail
export DEBIAN_FRONTEND=noninteractive

stamp=/var/lib/shadel-setup.stamp
want_version=7
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want_version" ] && [ "${SHADEL_FORCE_SETUP:-0}" != 1 ]; then
  echo "setup: already done (remove $stamp to redo)"
  exit 0
fi

SUDO=""
[ "$(id -u)" = 0 ] || SUDO=sudo

codename=$(. /etc/os-release && echo "${VERSION_CODENAME:-}")
backports=()
if [ "$codename" = bookworm ]; then
  if ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/ 2>/dev/null; then
    uri=""
    if [ -f /etc/apt/sources.list.d/debian.sources ]; then
      uri=$(awk '/^URIs:/{print $2; exit}' /etc/apt/sources.list.d/debian.sources)
    fi
    if [ -z "$uri" ] && [ -f /etc/apt/sources.list ]; then
      uri=$(awk '$1=="deb" && $3 ~ /^bookworm/ {print $2; exit}' /etc/apt/sources.list)
    fi
    if [ -z "$uri" ]; then
      echo "setup: cannot find the Debian mirror URI in /etc/apt/sources.list* to add bookworm-backports" >&2
      exit 1
    fi
    echo "deb $uri bookworm-backports main" | $SUDO tee /etc/apt/sources.list.d/shadel-backports.list >/dev/null
    echo "setup: added bookworm-backports from $uri"
  fi
  backports=(-t bookworm-backports)
fi

$SUDO apt-get update -qq
# Mesa (lavapipe) and the Vulkan loader from backports on bookworm.
$SUDO apt-get install -y -qq "${backports[@]}" mesa-vulkan-drivers libvulkan-dev libvulkan1 vulkan-tools
$SUDO apt-get install -y -qq \
  build-essential cmake ninja-build pkg-config git clang libclang-rt-14-dev \
  glslc libshaderc-dev spirv-tools vulkan-validationlayers \
  libglm-dev libtinygltf-dev libmeshoptimizer-dev libstb-dev libcli11-dev nlohmann-json3-dev \
  libgtest-dev libgmock-dev libbenchmark-dev libeigen3-dev assimp-testmodels python3 \
  gltfpack libtinyexr-dev libglfw3-dev libimgui-dev xvfb xauth xdotool
# The test suite's fuzz runs need clang with libFuzzer: fail here rather than skip them later.
if ! command -v clang++ >/dev/null 2>&1; then
  echo "setup: clang++ is missing after installing clang" >&2
  exit 1
fi
echo "$want_version" | $SUDO tee "$stamp" >/dev/null
echo "setup: done"
