#!/usr/bin/env bash
# Installs every Debian package the project needs to build, test and render its outputs.
# Idempotent: safe to run again. Needs root (or sudo) and access to Debian's package mirrors.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libsundials-dev        # CVODE: integration with root finding (events)
  libeigen3-dev          # vectors and matrices at the API
  libboost-graph-dev     # the mode graph
  libgtest-dev libgmock-dev
  librapidcheck-dev      # property tests; sampling in `hybrid check`
  libz3-dev              # Z3: SMT proofs in `hybrid check --method prove`
  libppl-dev             # PPL: exact polyhedra in `hybrid check --method reach`
  libpugixml-dev         # pugixml: SpaceEx models (`hybrid import`, .xml models)
  libceres-dev           # Ceres: robust refinement of fitted effects in `hybrid diagnose`
  libgoogle-perftools-dev  # tcmalloc_minimal: the hybrid program's allocator (docs/dependencies.md)
  libbenchmark-dev       # Google Benchmark
  tao-pegtl-dev          # the model-language grammar
  libcli11-dev           # the `hybrid` command line
  nlohmann-json3-dev     # --json output
  graphviz               # `dot -Tsvg` for the rendered mode graphs
  clang-format
  clang libclang-rt-14-dev  # libFuzzer harnesses (tests/fuzz/, tools/fuzz.sh) and their sanitizer runtimes
  python3                # tools/generate_finger.py (checked by a test), benchmark scripts
  python3-scipy python3-numpy  # tools/compare_scipy.py: the finger simulated by solve_ivp
  pybind11-dev python3-dev     # the Python module (python/, docs/python.md)
  python3-pytest               # its test suite (tests/python/)
  python3-jsonschema           # the JSON Schemas of the --json outputs (tests/python/test_json_schemas.py)
  python3-venv python3-pip python3-setuptools python3-wheel  # `pip install .` (pyproject.toml,
                               # docs/python.md "Installing") and its test (tests/python/test_pip_install.py)
)

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages already installed"
  exit 0
fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update
"${sudo_cmd[@]}" apt-get install -y --no-install-recommends "${packages[@]}"
