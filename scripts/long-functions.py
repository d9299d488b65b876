#!/usr/bin/env python3
"""Rust functions longer than a limit (100 lines by default), longest first.

    python3 scripts/long-functions.py [LIMIT]

Counts each `fn`'s lines from its signature to its closing brace, over every tracked
`.rs` file. Comments, strings and raw strings are blanked first (their newlines kept),
so braces inside them do not count. Exits with 1 when any is found: `.ci/run` holds
the code to the standard of no function over 100 lines (docs/architecture.md).
"""
import re
import subprocess
import sys

LIMIT = int(sys.argv[1]) if len(sys.argv) > 1 else 100

# Line and block comments, raw strings (r"..", r#".."#, ...), strings and char
# literals; each is replaced by spaces and its newlines.
TOKEN = re.compile(
    r'//[^\n]*|/\*.*?\*/|r(#*)".*?"\1|"(?:\\.|[^"\\])*"|\'(?:\\.|[^\'\\])\'',
    re.S,
)
FN = re.compile(r'\bfn\s+(\w+)')


def blank(text):
    return TOKEN.sub(lambda m: re.sub(r'[^\n]', ' ', m.group(0)), text)


def functions(path):
    text = blank(open(path, encoding='utf-8').read())
    for m in FN.finditer(text):
        depth, start = 0, None
        for i in range(m.end(), len(text)):
            c = text[i]
            if c == ';' and start is None:
                break  # a declaration without a body
            if c == '{':
                depth += 1
                start = start if start is not None else i
            elif c == '}':
                depth -= 1
                if depth == 0:
                    first = text.count('\n', 0, m.start()) + 1
                    last = text.count('\n', 0, i) + 1
                    yield last - first + 1, first, m.group(1)
                    break


def main():
    files = subprocess.check_output(['git', 'ls-files', '*.rs'], text=True).split()
    long = sorted(
        ((n, f, line, name) for f in files for n, line, name in functions(f) if n > LIMIT),
        reverse=True,
    )
    for n, f, line, name in long:
        print(f'{n:5} {f}:{line} {name}')
    print(f'{len(long)} function(s) over {LIMIT} lines')
    return 1 if long else 0


if __name__ == '__main__':
    sys.exit(main())
