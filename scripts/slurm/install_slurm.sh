#!/usr/bin/env bash
# Installs Slurm (controller, node daemon, client tools) and MUNGE from Debian if missing.
set -euo pipefail
packages=(munge slurmctld slurmd slurm-client)
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "installing Debian packages for a local Slurm cluster: ${missing[*]}"
# The packages' own services must not start: the test fixture starts the daemons itself.
install_cmd=(env DEBIAN_FRONTEND=noninteractive RUNLEVEL=1 apt-get install -y -qq
    --no-install-recommends "${missing[@]}")
if [ "$(id -u)" -eq 0 ]; then
    apt-get update -qq && "${install_cmd[@]}"
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
    sudo apt-get update -qq && sudo "${install_cmd[@]}"
else
    echo "ERROR: missing Debian packages ${missing[*]}; install them as root" >&2
    exit 1
fi
