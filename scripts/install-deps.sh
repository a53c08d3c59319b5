#!/usr/bin/env bash
# Install the Debian 12 packages prsm needs, only those missing. Run as root (or with sudo).
# Used by both README commands (make run, make test) through the Makefile.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libgsl-dev libnlopt-dev libmicrohttpd-dev libcjson-dev libsqlite3-dev nettle-dev
  librandom123-dev libcmocka-dev libmuparser-dev
  libopenmpi-dev openmpi-bin
  python3 python3-jsonschema python3-yaml python3-numpy python3-scipy
  chromium nodejs
)
# npm comes with NodeSource's nodejs; Debian packages it apart (the browser test runs npm ci)
if ! command -v npm >/dev/null 2>&1; then packages+=(npm); fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "prsm: installing missing packages: ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "prsm: need root to install: ${missing[*]}" >&2; exit 1; fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
