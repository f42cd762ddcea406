#!/bin/sh
# Installs every build and test dependency from Debian 12 packages. Idempotent; run as root.
set -eu
PACKAGES="build-essential cmake ninja-build pkg-config git
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers
  glslang-dev glslang-tools spirv-tools
  libglm-dev libsimdjson-dev libstb-dev libgtest-dev
  libcurl4-openssl-dev libcpp-httplib-dev
  libglfw3-dev libimgui-dev xvfb xauth gdb
  libfreetype-dev libfontconfig-dev fonts-dejavu-core zlib1g-dev libmeshoptimizer-dev
  libassimp-dev libexpat1-dev
  clang-14 libclang-rt-14-dev clang-format
  pybind11-dev python3-dev python3-numpy python3-pytest"
missing=""
for p in $PACKAGES; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    # shellcheck disable=SC2086
    apt-get install -y -qq --no-install-recommends $missing
fi
