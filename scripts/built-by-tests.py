#!/usr/bin/env python3
"""Prints the path of an executable that the README's test command built.

    python3 scripts/built-by-tests.py KIND NAME     # KIND: bin or example

`.ci/run` runs the fuzzer and the examples after the tests. `cargo run -p gnomon-fuzz`
would build them again: cargo unifies dependencies' features over the packages a
command selects, so `-p` builds another set of every crate whose features differ
from `--workspace`'s (63 crates for the fuzzer, 28 for the examples: about five
minutes on a 2-core machine). `cargo test --workspace` has already built both, so
this asks cargo, with the same selection, where they are. `--no-run` builds nothing
that is fresh; it fails, rather than guesses, if cargo names no such executable.
"""

import json
import subprocess
import sys


def main() -> int:
    if len(sys.argv) != 3 or sys.argv[1] not in ("bin", "example"):
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    kind, name = sys.argv[1], sys.argv[2]
    cargo = subprocess.run(
        ["cargo", "test", "--workspace", "--no-run", "--quiet", "--message-format=json"],
        stdout=subprocess.PIPE,
        check=True,
    )
    for line in cargo.stdout.decode().splitlines():
        message = json.loads(line)
        if message.get("reason") != "compiler-artifact" or not message.get("executable"):
            continue
        target = message["target"]
        # Test harnesses of the same name have `profile.test` set; the fuzzer's own
        # binary and the examples are built as they run.
        if target["name"] == name and kind in target["kind"] and not message["profile"]["test"]:
            print(message["executable"])
            return 0
    print(f"built-by-tests: `cargo test --workspace` built no {kind} called {name}", file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main())
