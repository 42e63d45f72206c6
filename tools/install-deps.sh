#!/usr/bin/env bash
# Installs psc's build and test dependencies from Debian packages.
# Idempotent: only missing packages are installed.  The CUDA Toolkit is
# expected at /usr/local/cuda (it is not a Debian package here).
set -euo pipefail

packages=(
  cmake ninja-build g++ pkg-config clang libclang-rt-dev
  antlr4 libantlr4-runtime-dev default-jre-headless
  libfmt-dev libcli11-dev catch2 nlohmann-json3-dev
  python3 python3-numpy python3-pytest python3-pil
  dpkg-dev file                                    # cpack -G DEB: the package's library dependencies
  python3-pip python3-setuptools python3-wheel     # pip install ./python, offline
  tmux                                             # tests/play: psc play driven in a terminal
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]} > 0)); then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  echo "installing: ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "all dependencies are installed"
fi
