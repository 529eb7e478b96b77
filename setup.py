"""The build of the Python package `hybrid` for pip (pyproject.toml; docs/python.md, "Installing").

setuptools makes the wheel; its build_ext step is CMake's: configure a build tree of this source for
the interpreter that runs pip, build the module's target (`_hybrid`, with the libraries it links),
and put the extension, the generated `_version.py` and the pure-Python files of python/hybrid/
into the wheel's package `hybrid`. The documentation goes to PREFIX/share/doc/hybrid/, as
`cmake --install` puts it. The version is CMake's project(VERSION ...) (CMakeLists.txt), the one
source of truth.

Environment (all optional):
  HYBRID_CMAKE_BUILD_DIR      an existing build tree of this source (e.g. build/) to build the
                              module in, used as it is configured: nothing is reconfigured, so its
                              Python must be the one running pip (checked). Unset: a tree of its
                              own, HYBRID_PIP_BUILD_DIR/cmake, configured (Release, no tests or
                              benchmarks) for the interpreter running pip and kept between runs.
  HYBRID_PIP_BUILD_DIR        where setuptools and that tree build (default: build-pip/ here).
  HYBRID_CMAKE_ARGS           more arguments for configuring that tree (split as a shell would).
  CMAKE_BUILD_PARALLEL_LEVEL  how many jobs build it (CMake's own variable).
"""

import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

SOURCE = Path(__file__).resolve().parent
BUILD_BASE = Path(os.environ.get("HYBRID_PIP_BUILD_DIR") or SOURCE / "build-pip").resolve()


def project_version():
    """The version in CMakeLists.txt's project(hybrid VERSION X.Y.Z ...)."""
    text = (SOURCE / "CMakeLists.txt").read_text(encoding="utf-8")
    found = re.search(r"^project\(\s*hybrid\s+VERSION\s+([0-9]+(?:\.[0-9]+)*)", text, re.M)
    if not found:
        raise RuntimeError("CMakeLists.txt: no project(hybrid VERSION ...) to take the version from")
    return found.group(1)


def run(command):
    print("setup.py: " + " ".join(shlex.quote(str(part)) for part in command), flush=True)
    subprocess.run([str(part) for part in command], check=True)


def cmake_cache_value(tree, name):
    cache = tree / "CMakeCache.txt"
    if not cache.is_file():
        return None
    for line in cache.read_text(encoding="utf-8", errors="replace").splitlines():
        if line.startswith(name + ":"):
            return line.split("=", 1)[1]
    return None


class CMakeBuild(build_ext):
    """build_ext as CMake: the module `hybrid._hybrid` built by the project's own CMake rules."""

    def build_extension(self, ext):
        if self.inplace:
            raise RuntimeError("an editable install (pip install -e) is not offered: the module is "
                               "compiled; build it with tools/build.sh and use PYTHONPATH=build/python")
        cmake = shutil.which("cmake")
        if cmake is None:
            raise RuntimeError("CMake not found (Debian: cmake; tools/setup.sh installs it)")
        tree = self.configured_tree(cmake)
        run([cmake, "--build", tree, "--target", "_hybrid"])
        built = tree / "python" / "hybrid"
        extension = built / ("_hybrid" + sysconfig.get_config_var("EXT_SUFFIX"))
        if not extension.is_file():
            present = sorted(p.name for p in built.glob("_hybrid*")) or "no module"
            raise RuntimeError(
                f"{tree} built {present} for another Python than {sys.executable} "
                f"(which needs {extension.name}); unset HYBRID_CMAKE_BUILD_DIR to build a tree "
                f"for this one")
        version_file = built / "_version.py"
        if f'"{project_version()}"' not in version_file.read_text(encoding="utf-8"):
            raise RuntimeError(f"{version_file} is not of version {project_version()}")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(extension, target)
        shutil.copy2(version_file, target.parent / "_version.py")
        for name in ("__init__.py", "__init__.pyi", "py.typed"):
            shutil.copy2(SOURCE / "python" / "hybrid" / name, target.parent / name)

    def configured_tree(self, cmake):
        """The build tree: HYBRID_CMAKE_BUILD_DIR as it is, or one of its own, (re)configured."""
        given = os.environ.get("HYBRID_CMAKE_BUILD_DIR")
        if given:
            tree = Path(given).resolve()
            home = cmake_cache_value(tree, "CMAKE_HOME_DIRECTORY")
            if home is None or Path(home).resolve() != SOURCE:
                raise RuntimeError(f"HYBRID_CMAKE_BUILD_DIR={given} is no configured build tree "
                                   f"of {SOURCE}")
            return tree
        tree = BUILD_BASE / "cmake"
        configure = [cmake, "-S", SOURCE, "-B", tree, "-DCMAKE_BUILD_TYPE=Release",
                     "-DHYBRID_BUILD_PROGRAM=ON", "-DHYBRID_BUILD_PYTHON=ON",
                     "-DHYBRID_BUILD_TESTS=OFF", "-DHYBRID_BUILD_BENCHMARKS=OFF",
                     f"-DPython_EXECUTABLE={sys.executable}"]
        if not (tree / "CMakeCache.txt").is_file() and shutil.which("ninja"):
            configure += ["-G", "Ninja"]
        configure += shlex.split(os.environ.get("HYBRID_CMAKE_ARGS", ""))
        run(configure)
        return tree


def documentation():
    """docs/ (with README, CHANGELOG and the licences) for PREFIX/share/doc/hybrid/."""
    files = {}
    for path in sorted((SOURCE / "docs").rglob("*")):
        if path.is_file():
            folder = Path("share/doc/hybrid") / path.parent.relative_to(SOURCE / "docs")
            files.setdefault(folder.as_posix(), []).append(path.relative_to(SOURCE).as_posix())
    files["share/doc/hybrid"] += ["README.md", "CHANGELOG.md", "LICENSE", "LICENSE.GPL-3.0"]
    return sorted(files.items())


BUILD_BASE.mkdir(parents=True, exist_ok=True)
setup(
    version=project_version(),
    packages=[],  # the package `hybrid` is put together by CMakeBuild
    ext_modules=[Extension("hybrid._hybrid", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    data_files=documentation(),
    zip_safe=False,
    options={"build": {"build_base": str(BUILD_BASE)},
             "egg_info": {"egg_base": str(BUILD_BASE)}},
)
