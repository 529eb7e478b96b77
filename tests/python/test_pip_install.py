"""hybrid installed as a Python package (docs/python.md, "Installing"; pyproject.toml, setup.py).

`pip install --no-build-isolation --no-index SOURCE` into a fresh virtual environment made by
Debian's python3-venv with the system's site packages (numpy, setuptools, wheel), then `import
hybrid` in a folder outside the source tree, without PYTHONPATH: its `__version__` is CMake's
project version, its extension computes, the documentation and the licences are installed.

Which build pip does: by default setup.py builds the module in this build tree
(HYBRID_CMAKE_BUILD_DIR = HYBRID_BUILD_DIR, which ctest sets): after the suite's build the module
is up to date there, so the install takes seconds and checks everything but the configuration of
a tree of its own. With HYBRID_TEST_PIP_FRESH=1, pip configures and builds a tree of its own from
nothing, as a user's `pip install .` does (about 5 minutes on two cores: ctest's timeout of this
test is half an hour).

Run by ctest as `pip_install`, apart from the rest of tests/python (tests/CMakeLists.txt).
"""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

SOURCE = Path(os.environ.get("HYBRID_SOURCE_DIR", Path(__file__).resolve().parents[2]))


def project_version():
    text = (SOURCE / "CMakeLists.txt").read_text()
    return re.search(r"^project\(\s*hybrid\s+VERSION\s+([0-9.]+)", text, re.M).group(1)


def run(command, **kwargs):
    result = subprocess.run([str(c) for c in command], capture_output=True, text=True, **kwargs)
    assert result.returncode == 0, (
        f"{' '.join(map(str, command))} exited {result.returncode}\n"
        f"--- stdout\n{result.stdout[-6000:]}\n--- stderr\n{result.stderr[-6000:]}")
    return result.stdout


def test_the_version_is_the_projects():
    import hybrid  # the build tree's module (PYTHONPATH)

    assert hybrid.__version__ == project_version()
    assert re.fullmatch(r"[0-9]+\.[0-9]+\.[0-9]+", hybrid.__version__)
    binary = os.environ.get("HYBRID_BINARY")
    if binary:
        assert run([binary, "--version"]) == f"hybrid {project_version()}\n"


def test_pip_install_into_a_fresh_virtual_environment(tmp_path):
    venv = tmp_path / "venv"
    run([sys.executable, "-m", "venv", "--system-site-packages", venv])
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["HYBRID_PIP_BUILD_DIR"] = str(tmp_path / "pip-build")
    env.pop("HYBRID_CMAKE_BUILD_DIR", None)
    if os.environ.get("HYBRID_TEST_PIP_FRESH") != "1":
        env["HYBRID_CMAKE_BUILD_DIR"] = os.environ["HYBRID_BUILD_DIR"]
    python = venv / "bin" / "python"
    run([python, "-m", "pip", "install", "--no-build-isolation", "--no-index",
         "--disable-pip-version-check", SOURCE], cwd=tmp_path, env=env)

    outside = tmp_path / "elsewhere"
    outside.mkdir()
    probe = ("import hybrid, json; print(json.dumps({'version': hybrid.__version__, "
             "'file': hybrid.__file__, 'angles': hybrid.finger_angles(153.5).tolist()}))")
    found = json.loads(run([python, "-c", probe], cwd=outside, env=env))
    assert found["version"] == project_version()
    assert Path(found["file"]).resolve().is_relative_to(venv.resolve())
    assert [round(a, 6) for a in found["angles"][0]] == [70.0, 12.15, -55.0]

    # The documentation as `cmake --install` lays it out, and the licences with the metadata.
    docs = venv / "share" / "doc" / "hybrid"
    for name in ("cli.md", "python.md", "dependencies.md", "schemas/simulate.schema.json",
                 "README.md", "CHANGELOG.md", "LICENSE", "LICENSE.GPL-3.0"):
        assert (docs / name).is_file(), name
    metadata = run([python, "-m", "pip", "show", "--files", "hybrid"], cwd=outside, env=env)
    assert f"Version: {project_version()}" in metadata
    assert "LICENSE.GPL-3.0" in metadata
    assert "hybrid/__init__.pyi" in metadata and "hybrid/py.typed" in metadata
