#!/bin/sh
# Installs the system packages Gnomon needs, where they are missing (Debian/Ubuntu):
# - a Vulkan driver: on a machine without a GPU, Mesa's CPU driver lavapipe
#   (mesa-vulkan-drivers);
# - a C++ compiler, for meshoptimizer (the `meshopt` crate builds its C++ source);
# - with --tests, an X server for the viewer's window test when there is no display
#   (xvfb, whose xvfb-run the test starts itself), and a lavapipe with ray queries in
#   a folder of its own for the ray-query tests (fetch-lavapipe-ray-query.sh: the
#   system's Mesa is left as it is);
# - with --browser, Debian's Chromium and Node.js with npm, for the lab's browser
#   test (web/test/browser-test.mjs; docs/web.md);
# - with --python, Python's venv module (Debian ships it apart, in python3-venv),
#   for `pip install ./python` in a fresh virtual environment (docs/python.md).
# Does nothing when everything is already there.
set -eu

want_tests=no
want_browser=no
want_python=no
for arg in "$@"; do
    case "$arg" in
        --tests) want_tests=yes ;;
        --browser) want_browser=yes ;;
        --python) want_python=yes ;;
        *) echo "install-system-deps: unknown option $arg (give --tests, --browser, --python or nothing)" >&2; exit 2 ;;
    esac
done

have_icd=no
for f in /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json; do
    [ -e "$f" ] && have_icd=yes
done
have_loader=no
for f in /usr/lib/*/libvulkan.so.1 /usr/lib/libvulkan.so.1 /usr/lib64/libvulkan.so.1; do
    [ -e "$f" ] && have_loader=yes
done

packages=""
if [ "$have_icd" = no ] || [ "$have_loader" = no ]; then
    echo "install-system-deps: no Vulkan driver found; installing lavapipe (mesa-vulkan-drivers)" >&2
    packages="mesa-vulkan-drivers libvulkan1"
fi
if ! command -v c++ >/dev/null 2>&1 && ! command -v g++ >/dev/null 2>&1; then
    echo "install-system-deps: no C++ compiler; installing g++ for meshoptimizer" >&2
    packages="$packages g++"
fi
if [ "$want_tests" = yes ] && ! command -v xvfb-run >/dev/null 2>&1; then
    echo "install-system-deps: no xvfb-run; installing xvfb for the viewer's window test" >&2
    packages="$packages xvfb xauth"
fi
if [ "$want_browser" = yes ] && ! [ -x /usr/bin/chromium ]; then
    echo "install-system-deps: no chromium; installing Debian's for the browser test" >&2
    packages="$packages chromium"
fi
if [ "$want_browser" = yes ] && ! command -v npm >/dev/null 2>&1; then
    echo "install-system-deps: no npm; installing Node.js for the browser test's driver" >&2
    packages="$packages nodejs npm"
fi
if [ "$want_python" = yes ] && ! python3 -c 'import venv, ensurepip' >/dev/null 2>&1; then
    echo "install-system-deps: no Python venv module; installing python3-venv for the Python package" >&2
    packages="$packages python3-venv"
fi
# The ray-query tests skip, saying so, without it: a failed fetch is no failure here.
fetch_ray_query() {
    if [ "$want_tests" = yes ]; then
        sh "$(dirname "$0")/fetch-lavapipe-ray-query.sh" ||
            echo "install-system-deps: no lavapipe with ray queries fetched; the ray-query tests will skip" >&2
    fi
}
if [ -z "$packages" ]; then
    fetch_ray_query
    exit 0
fi

if ! command -v apt-get >/dev/null 2>&1; then
    echo "install-system-deps: missing $packages and no apt-get; install your platform's Vulkan driver (on Mesa systems: lavapipe), a C++ compiler and, for the tests, an X server such as Xvfb" >&2
    exit 1
fi

SUDO=""
if [ "$(id -u)" != "0" ]; then
    SUDO="sudo"
fi
$SUDO apt-get update -qq
# shellcheck disable=SC2086 # the package list is meant to split
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $packages >/dev/null
fetch_ray_query
