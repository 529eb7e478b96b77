"""Every command of the README's "Using it" block runs as written (from a scratch directory in
which build/, spec/, data/ and tools/ are the repository's): exit 0, or the documented verdict
codes of `hybrid check` (6 a property violated, 7 a verdict unknown) where the README says so.
A command another test already runs the same way (COVERED) is left to that test."""

import os
import re
import subprocess

import pytest

SOURCE = os.environ.get("HYBRID_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
BINARY = os.environ.get("HYBRID_BINARY", os.path.join(SOURCE, "build", "bin", "hybrid"))
BUILD = os.path.dirname(os.path.dirname(os.path.abspath(BINARY)))


def readme_commands():
    with open(os.path.join(SOURCE, "README.md")) as f:
        text = f.read()
    block = re.search(r"## Using it\n\n```sh\n(.*?)```", text, re.S).group(1)
    commands = []
    for line in block.splitlines():
        command = re.sub(r"\s+#\s.*$", "", line).strip()  # the comment after the command
        if command:
            commands.append(command)
    return commands


# Commands whose documented outcome is a verdict other than "all proved".
VERDICT_CODES = {"fischer_2_unsafe.ha": 6, "--method sample": 7}

# Commands that another test runs as written here and checks at least as strictly: skipped
# here while that test exists. command -> (its source file, the test's name).
COVERED = {
    # --require-all as well (exit 0 only if every verdict is decided and expected), from the
    # same layout with the script's default binary.
    "python3 tools/benchmarks.py --quick":
        ("tests/tools/benchmarks_test.cc", "BenchmarksTest, QuickSubsetIsDecidedAsExpected"),
}


def covered_by(command):
    """The test that runs `command` in place of this one, or None."""
    if command not in COVERED:
        return None
    source, test = COVERED[command]
    path = os.path.join(SOURCE, source)
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return test if "TEST(" + test + ")" in f.read() else None


@pytest.mark.parametrize("command", readme_commands())
def test_readme_command_runs(tmp_path, command):
    other = covered_by(command)
    if other:
        pytest.skip("run and checked by " + other.replace(", ", "."))
    for name in ("spec", "data", "tools"):
        os.symlink(os.path.join(SOURCE, name), tmp_path / name)
    os.symlink(BUILD, tmp_path / "build")
    run = subprocess.run(command, shell=True, cwd=tmp_path, capture_output=True, text=True,
                         timeout=600, env=dict(os.environ, PYTHONPATH=os.path.join(BUILD, "python")))
    expected = next((code for key, code in VERDICT_CODES.items() if key in command), 0)
    assert run.returncode == expected, command + "\n" + run.stderr[-2000:]
