#!/usr/bin/env python3
"""Lists the longest functions of the project's C++ sources (docs/architecture.md, "Habits").

Usage: tools/function_sizes.py [--over N] [--max M] [--allow K] [paths...]
  --over N   list the functions longer than N lines (default 100)
  --max M    exit 1 if any function is longer than M lines (default 150)
  --allow K  ... or if more than K functions are longer than N lines (default 5)
  paths      files or folders (default: automaton solvers gripper plotting commands cli python
             include)

A function's length is the number of lines from its opening brace to its closing one, both
included; lambdas and local classes count towards the function that holds them. The scan is
lexical (comments, strings and character literals skipped; braces matched): a brace opens a
function body when every brace around it belongs to a namespace, class, struct or union and the
code before it ends a parameter list (`)`, possibly followed by qualifiers or a trailing return
type or constructor initialisers).
"""
import argparse
import os
import re
import sys

SCOPE = re.compile(r"\b(namespace|class|struct|union|enum)\b[^;{}()]*$")
QUALIFIERS = re.compile(r"\)\s*(const|override|final|noexcept|mutable|volatile|&|&&|\s)*"
                        r"(->\s*[\w:<>,\s*&]+)?$")
INITIALISERS = re.compile(r"\)\s*:\s*[\w:]+\s*[({].*[)}]\s*$", re.S)


def strip(text):
    """Blanks comments, string and character literals, keeping newlines and offsets."""
    out = list(text)
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
        elif c == 'R' and text.startswith('R"', i) and (i == 0 or not text[i - 1].isalnum()):
            k = text.find("(", i)
            delim = ")" + text[i + 2:k] + '"'
            j = text.find(delim, k)
            j = n if j < 0 else j + len(delim)
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            j += 1
            if c == "'" and i > 0 and text[i - 1].isalnum():  # digit separator 1'000
                i += 1
                continue
        elif c == "#" and (i == 0 or text[i - 1] == "\n"):
            j = i
            while j < n and text[j] != "\n":
                j += 2 if text.startswith("\\\n", j) else 1
        else:
            i += 1
            continue
        for k in range(i, min(j, n)):
            if out[k] != "\n":
                out[k] = " "
        i = j
    return "".join(out)


def functions(path):
    """Yields (line, name, length) of every function defined in `path`."""
    with open(path, encoding="utf-8", errors="replace") as f:
        text = strip(f.read())
    stack = []  # one entry per open brace: "scope", "function" or "other"
    start = 0  # where the code before the next brace begins
    for i, c in enumerate(text):
        if c in ";":
            start = i + 1
        elif c == "{":
            before = text[start:i].strip()
            kind = "other"
            if all(entry[0] == "scope" for entry in stack):
                if SCOPE.search(before) or before.startswith("extern"):
                    kind = "scope"
                elif before and (QUALIFIERS.search(before) or INITIALISERS.search(before)):
                    kind = "function"
            stack.append((kind, i, before))
            start = i + 1
        elif c == "}":
            if not stack:
                continue
            kind, opened, before = stack.pop()
            if kind == "function":
                first = text.count("\n", 0, opened) + 1
                last = text.count("\n", 0, i) + 1
                name = re.sub(r"\s+", " ", before.split("(")[0]).split(" ")[-1]
                yield first, name, last - first + 1
            start = i + 1


def sources(paths):
    for p in paths:
        if os.path.isfile(p):
            yield p
            continue
        for root, _, files in os.walk(p):
            for f in sorted(files):
                if f.endswith((".cc", ".h")):
                    yield os.path.join(root, f)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--over", type=int, default=100)
    parser.add_argument("--max", type=int, default=150)
    parser.add_argument("--allow", type=int, default=5)
    parser.add_argument("paths", nargs="*",
                        default=["automaton", "solvers", "gripper", "plotting", "commands", "cli",
                                 "python", "include"])
    args = parser.parse_args()
    found = []
    for path in sources(args.paths):
        for line, name, length in functions(path):
            found.append((length, path, line, name))
    found.sort(reverse=True)
    long = [f for f in found if f[0] > args.over]
    for length, path, line, name in long:
        print(f"{length:5d}  {path}:{line}  {name}")
    worst = found[0][0] if found else 0
    print(f"{len(found)} functions; {len(long)} over {args.over} lines; the longest has {worst}")
    if worst > args.max or len(long) > args.allow:
        print(f"function_sizes: at most {args.allow} functions over {args.over} lines and none over "
              f"{args.max} allowed", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
