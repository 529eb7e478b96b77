#!/usr/bin/env python3
"""Collects the seed corpus of one libFuzzer harness (run by tools/fuzz.sh; docs/fuzzing.md).

Usage: collect_seeds.py SOURCE_DIR HARNESS OUT_DIR

Writes each seed to OUT_DIR under the SHA-1 of its content (so repeated collection into a
corpus that libFuzzer has grown adds nothing twice). Seeds come from the repository at run time,
never from a committed generated corpus:
  fuzz_model_parser, fuzz_round_trip: spec/*.ha, every .ha under tests/, and the model texts of
      the tests (raw string literals R"(...)" of tests/**/*.cc and *.h that declare an automaton);
  fuzz_signal: tests/fuzz/seeds/fuzz_signal/ and the step(...)/linear(...) signals written in
      spec/ and tests/;
  fuzz_object: tests/fuzz/seeds/fuzz_object/ and the "circle:..."/"segment:..." strings of tests/;
  fuzz_measured_data: tests/fuzz/seeds/fuzz_measured_data/ and the first rows of data/*.csv;
  fuzz_spaceex: spec/spaceex/*.xml, each alone and followed by a NUL byte and its .cfg;
  any harness: tests/fuzz/seeds/HARNESS/ if it exists.
Prints the number of seeds written.
"""

import hashlib
import pathlib
import re
import sys

MAX_SEED_BYTES = 64 * 1024
CSV_HEAD_LINES = 40

RAW_STRING = re.compile(r'R"([^()\\\s]{0,16})\((.*?)\)\1"', re.S)
SIGNAL = re.compile(r"\b(?:step|linear)\([^()\"\n]*\)")
OBJECT = re.compile(r'"((?:circle|segment):[^"\n]*)"')
DECLARES_MODEL = re.compile(r"\b(?:automaton|system)\s+[A-Za-z_]\w*\s*\{")


def sources(root, patterns):
    for pattern in patterns:
        yield from sorted(root.glob(pattern))


def model_seeds(root):
    for path in sources(root, ["spec/*.ha", "tests/**/*.ha"]):
        yield path.read_bytes()
    for path in sources(root, ["tests/**/*.cc", "tests/**/*.h"]):
        for match in RAW_STRING.finditer(path.read_text(errors="replace")):
            if DECLARES_MODEL.search(match.group(2)):
                yield match.group(2).encode()


def signal_seeds(root):
    for path in sources(root, ["spec/*.ha", "tests/**/*.cc", "tests/**/*.ha"]):
        for match in SIGNAL.finditer(path.read_text(errors="replace")):
            yield match.group(0).encode()


def object_seeds(root):
    for path in sources(root, ["tests/**/*.cc", "docs/*.md", "README.md"]):
        for match in OBJECT.finditer(path.read_text(errors="replace")):
            yield match.group(1).encode()


def measured_data_seeds(root):
    for path in sources(root, ["data/*.csv"]):
        with path.open("rb") as f:
            yield b"".join(line for _, line in zip(range(CSV_HEAD_LINES), f))


def spaceex_seeds(root):
    for path in sources(root, ["spec/spaceex/*.xml"]):
        yield path.read_bytes()
        cfg = path.with_suffix(".cfg")
        if cfg.is_file():
            yield path.read_bytes() + b"\0" + cfg.read_bytes()


COLLECTORS = {
    "fuzz_model_parser": model_seeds,
    "fuzz_round_trip": model_seeds,
    "fuzz_signal": signal_seeds,
    "fuzz_object": object_seeds,
    "fuzz_measured_data": measured_data_seeds,
    "fuzz_spaceex": spaceex_seeds,
}


def main(argv):
    if len(argv) != 4:
        sys.exit(__doc__)
    root, harness, out = pathlib.Path(argv[1]), argv[2], pathlib.Path(argv[3])
    out.mkdir(parents=True, exist_ok=True)
    seeds = []
    committed = root / "tests" / "fuzz" / "seeds" / harness
    if committed.is_dir():
        seeds += [p.read_bytes() for p in sorted(committed.iterdir()) if p.is_file()]
    if harness in COLLECTORS:
        seeds += list(COLLECTORS[harness](root))
    written = 0
    for seed in seeds:
        if not seed or len(seed) > MAX_SEED_BYTES:
            continue
        target = out / hashlib.sha1(seed).hexdigest()
        if not target.exists():
            target.write_bytes(seed)
            written += 1
    print(written)


if __name__ == "__main__":
    main(sys.argv)
