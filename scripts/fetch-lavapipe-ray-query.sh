#!/bin/sh
# Fetches a lavapipe that has ray queries (Mesa 24.1 or later, which implements
# VK_KHR_acceleration_structure and VK_KHR_ray_query on the CPU) into a folder of its
# own, without installing it: the system's Mesa stays the one every other test and
# figure uses. The ray-query tests (crates/reference/tests/ray_queries.rs) run
# themselves again on it where the system's Vulkan has no ray queries.
#
#   sh scripts/fetch-lavapipe-ray-query.sh [DIR]     (default: target/lavapipe-ray-query)
#
# On Debian 12 (bookworm) it takes Mesa from bookworm-backports, with the libdrm
# that Mesa needs, through apt with a private list and cache (nothing on the system
# changes), and writes DIR/lvp_icd.json for VK_DRIVER_FILES and DIR/lib for
# LD_LIBRARY_PATH. Elsewhere it says what it would need and exits 0: the tests then
# print that they skipped. Does nothing if DIR already holds a driver.
set -eu

dir=${1:-$(dirname "$0")/../target/lavapipe-ray-query}
if [ -e "$dir/lvp_icd.json" ]; then
    exit 0
fi
say() { echo "fetch-lavapipe-ray-query: $*" >&2; }

if [ "$(cat /etc/debian_version 2>/dev/null | cut -d. -f1)" != "12" ] || [ "$(dpkg --print-architecture 2>/dev/null)" != "amd64" ]; then
    say "not Debian 12 on amd64: no lavapipe with ray queries fetched (install Mesa 24.1 or later to run the ray-query tests)"
    exit 0
fi
for tool in apt-get dpkg-deb; do
    if ! command -v "$tool" >/dev/null 2>&1; then
        say "no $tool: no lavapipe with ray queries fetched"
        exit 0
    fi
done

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/lists/partial" "$work/cache/archives/partial" "$work/debs"
echo "deb [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] http://deb.debian.org/debian bookworm-backports main" \
    > "$work/sources.list"
apt() {
    apt-get -qq -o Dir::Etc::SourceList="$work/sources.list" -o Dir::Etc::SourceParts=/dev/null \
        -o Dir::State::Lists="$work/lists" -o Dir::Cache="$work/cache" -o Debug::NoLocking=1 \
        -o APT::Sandbox::User=root "$@"
}
say "fetching Mesa's lavapipe from bookworm-backports into $dir"
if ! apt update || ! (cd "$work/debs" && apt download mesa-vulkan-drivers/bookworm-backports \
        libdrm2/bookworm-backports libdrm-amdgpu1/bookworm-backports); then
    say "could not fetch it (no network?): the ray-query tests will skip"
    exit 0
fi

staged="$dir.partial"
rm -rf "$staged"
mkdir -p "$staged/root" "$staged/lib"
for deb in "$work"/debs/*.deb; do
    dpkg-deb -x "$deb" "$staged/root"
done
cp -a "$staged"/root/usr/lib/x86_64-linux-gnu/libvulkan_lvp.so "$staged"/root/usr/lib/x86_64-linux-gnu/libdrm*.so* "$staged/lib/"
rm -rf "$staged/root"
# The driver's absolute path once the folder is in place.
final=$(cd "$staged" && pwd)
final=${final%.partial}
cat > "$staged/lvp_icd.json" <<EOF
{
    "file_format_version": "1.0.0",
    "ICD": { "library_path": "$final/lib/libvulkan_lvp.so", "api_version": "1.3.0" }
}
EOF
rm -rf "$dir"
mv "$staged" "$dir"
say "wrote $dir/lvp_icd.json ($(ls "$work"/debs | grep mesa-vulkan))"
