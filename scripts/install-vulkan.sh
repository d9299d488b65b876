#!/bin/sh
# Makes sure a Vulkan driver is present. On a machine without a GPU this installs
# Mesa's CPU Vulkan driver, lavapipe (Debian/Ubuntu package mesa-vulkan-drivers).
# Does nothing when a Vulkan driver (ICD) is already installed.
set -eu

have_icd=no
for f in /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json; do
    [ -e "$f" ] && have_icd=yes
done
have_loader=no
for f in /usr/lib/*/libvulkan.so.1 /usr/lib/libvulkan.so.1 /usr/lib64/libvulkan.so.1; do
    [ -e "$f" ] && have_loader=yes
done
if [ "$have_icd" = yes ] && [ "$have_loader" = yes ]; then
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
