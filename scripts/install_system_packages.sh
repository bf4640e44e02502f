#!/usr/bin/env bash
# Installs the Debian packages the project needs, if missing: off-screen rendering (pyvista/VTK
# with EGL) and LIGGGHTS 3.8 with OpenMPI (the decks are checked against it in tests/liggghts).
# No recommended packages: liggghts recommends ParaView, which nothing here uses.
set -euo pipefail
packages=(libegl1 libegl-mesa0 libgl1-mesa-dri liggghts openmpi-bin)
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "installing Debian packages (off-screen rendering, LIGGGHTS, OpenMPI): ${missing[*]}"
if [ "$(id -u)" -eq 0 ]; then
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
elif command -v sudo >/dev/null 2>&1; then
    sudo apt-get update -qq && sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
    echo "ERROR: missing Debian packages ${missing[*]}; install them as root" >&2
    exit 1
fi
