#!/usr/bin/env python3
"""Writes the chain of N constant-rate modes used to measure `hybrid check --budget`
(docs/verification.md, "The budget"): mode m_i has x' = 1 and x <= i + 1, transition t_i leaves
it for m_(i+1) at x >= i + 1; `bounded: always x <= N` holds, `far: reach x >= N - 0.5` needs
N jumps.

Usage: tools/chain_model.py N [FILE]      (default FILE: standard output)
"""
import sys


def chain(n: int) -> str:
    lines = ["automaton chain {", "  var x;"]
    lines += [f"  mode m{i} {{ x' = 1; inv x <= {i + 1}; }}" for i in range(n)]
    lines += [f"  transition t{i}: m{i} -> m{i + 1} {{ guard x >= {i + 1}; }}" for i in range(n - 1)]
    lines += ["  init m0 { x = 0; }", f"  property bounded: always x <= {n};",
              f"  property far: reach x >= {n - 0.5};", "}"]
    return "\n".join(lines) + "\n"


def main() -> int:
    if len(sys.argv) not in (2, 3) or not sys.argv[1].isdigit() or int(sys.argv[1]) < 1:
        print(__doc__.strip().splitlines()[-1], file=sys.stderr)
        return 2
    text = chain(int(sys.argv[1]))
    if len(sys.argv) == 3:
        with open(sys.argv[2], "w", encoding="utf-8") as out:
            out.write(text)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
