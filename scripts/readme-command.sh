#!/bin/sh
# Prints the README's Nth `sh` code block (1 and 2: the two commands the README opens
# with; 4: the Python package's install), exactly as the README writes it, so that `.ci/run` runs what a newcomer
# copies and the two can never drift apart.
#
#   sh scripts/readme-command.sh N [README]
set -eu
n=$1
readme=${2:-"$(dirname "$0")/../README.md"}
block=$(awk -v n="$n" '
  /^```sh$/ && !inside { inside = 1; count++; next }
  /^```/ && inside { inside = 0; if (count == n) exit; next }
  inside && count == n { print }
' "$readme")
if [ -z "$block" ]; then
  echo "readme-command: $readme has no sh code block number $n" >&2
  exit 1
fi
printf '%s\n' "$block"
