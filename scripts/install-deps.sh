#!/bin/sh
# Installs what ptr builds and tests with, from Debian 12's packages.
set -eu
run() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }
run apt-get update -qq
DEBIAN_FRONTEND=noninteractive run apt-get install -y -qq --no-install-recommends \
    build-essential cmake pkg-config python3 nasm \
    libopenexr-dev libopenimageio-dev openimageio-tools libopencolorio-dev opencolorio-tools \
    libtinygltf-dev libmeshoptimizer-dev nlohmann-json3-dev gemmi-dev tao-pegtl-dev zlib1g-dev parallel \
    libmicrohttpd-dev libpng-dev chromium chromium-driver python3-selenium >/dev/null

