#!/usr/bin/env bash
# Installs what the build and tests need from Debian's packages, and moves the machine into
# the ParaView state: python3-paraview conflicts with python3-vtk9 (pulled in by libvtk9-dev),
# and find_package(ParaView) only configures with python3-paraview installed.
# ParaView's CMake package needs MPI's headers (libopenmpi-dev) to configure, and its
# rendering modules need GLEW's, X11's and OpenGL's (libglew-dev, libx11-dev, libgl-dev).
# Idempotent: when everything is present it only runs dpkg-query and returns.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  paraview paraview-dev python3-paraview
  libcgal-dev libembree-dev libtbb-dev libgtest-dev libbenchmark-dev libnova-dev nlohmann-json3-dev
  xvfb python3-numpy python3-pytest python3-matplotlib
  libopenmpi-dev openmpi-bin libglew-dev libx11-dev libgl-dev libpng-dev
  clang libclang-rt-14-dev
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  if [ "$status" != "installed" ]; then missing+=("$p"); fi
done
# python3-vtk9 must go: it conflicts with python3-paraview.
conflicting=()
for p in python3-vtk9 libvtk9-dev; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  if [ "$status" = "installed" ]; then conflicting+=("$p-"); fi
done

if [ ${#missing[@]} -eq 0 ] && [ ${#conflicting[@]} -eq 0 ]; then
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "setup: installing ${missing[*]:-} ${conflicting[*]:-}" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" "${conflicting[@]}" >/dev/null
