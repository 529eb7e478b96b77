#!/usr/bin/env python3
"""Writes two models just under the 16 MiB model-file limit (automaton/parser.h kMaxModelFileBytes)
that make the parser use more than 2 GB of memory (tests/fuzz/findings/README.md).

Usage: large_models.py DIR    (writes DIR/long_sum.ha and DIR/long_invariant.ha)
"""
import pathlib
import sys

out = pathlib.Path(sys.argv[1])
terms = "+".join(["1"] * 8_000_000)
(out / "long_sum.ha").write_text(
    f"automaton a {{ var x; param p = {terms}; mode m {{ x' = p; }} init m {{ x = 0; }} }}\n")
conjuncts = "inv x <= 1; " * 1_333_300
(out / "long_invariant.ha").write_text(
    f"automaton a {{ var x; mode m {{ {conjuncts}}} init m {{ x = 0; }} }}\n")
