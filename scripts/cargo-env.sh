# Sourced by setup.sh and test.sh once .venv exists: the environment every cargo command of
# theirs runs in, so that cargo, maturin and the test suites share one build.
#
# maturin runs cargo with PYO3_PYTHON and PYO3_ENVIRONMENT_SIGNATURE naming the interpreter
# it builds for; pyo3's build script reruns when either changes, and pyo3, numpy and the
# extension recompile. Plain cargo gets the values maturin passes for .venv's Python.
PYO3_PYTHON="$PWD/.venv/bin/python3"
PYO3_ENVIRONMENT_SIGNATURE=$("$PYO3_PYTHON" -c 'import sys; v = sys.version_info
print(f"{sys.implementation.name}-{v.major}.{v.minor}-{64 if sys.maxsize > 2**32 else 32}bit")')
export PYO3_PYTHON PYO3_ENVIRONMENT_SIGNATURE
