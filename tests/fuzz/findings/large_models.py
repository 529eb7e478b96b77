#!/usr/bin/env python3
"""Writes two models just under the model size limit (include/hybrid/automaton/parser.h kMaxModelFileBytes,
4 MiB; another limit in bytes may be given) that stress the parser's memory
(tests/fuzz/findings/README.md).

Usage: large_models.py DIR [LIMIT]   (writes DIR/long_sum.ha and DIR/long_invariant.ha)
"""
import pathlib
import sys

out = pathlib.Path(sys.argv[1])
limit = int(sys.argv[2]) if len(sys.argv) > 2 else 4 << 20
terms = "+".join(["1"] * ((limit - 200) // 2))
(out / "long_sum.ha").write_text(
    f"automaton a {{ var x; param p = {terms}; mode m {{ x' = p; }} init m {{ x = 0; }} }}\n")
conjuncts = "inv x <= 1; " * ((limit - 200) // 12)
(out / "long_invariant.ha").write_text(
    f"automaton a {{ var x; mode m {{ {conjuncts}}} init m {{ x = 0; }} }}\n")
