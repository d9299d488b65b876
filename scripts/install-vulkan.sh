#!/bin/sh
# Makes sure a Vulkan driver is present. On a machine without a GPU this installs
# Mesa's CPU Vulkan driver, lavapipe (Debian/Ubuntu package mesa-vulkan-drivers).
# Does nothing when a Vulkan driver (ICD) is already installed.
set -eu

if ls /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json >/dev/null 2>&1 \
    && ldconfig -p 2>/dev/null | grep -q 'libvulkan\.so\.1'; then
    exit 0
fi

if ! command -v apt-get >/dev/null 2>&1; then
    echo "install-vulkan: no Vulkan driver found and no apt-get; install your platform's Vulkan driver (on Mesa systems: lavapipe)" >&2
    exit 1
fi

SUDO=""
if [ "$(id -u)" != "0" ]; then
    SUDO="sudo"
fi
echo "install-vulkan: no Vulkan driver found; installing lavapipe (mesa-vulkan-drivers)" >&2
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq mesa-vulkan-drivers libvulkan1 >/dev/null
