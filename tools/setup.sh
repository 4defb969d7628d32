#!/usr/bin/env bash
# Sets up what is missing, idempotently: the Python environment in .venv (the project
# installed editable with its test extras). A second run only checks a stamp and returns.
# Engines (LIGGGHTS, OpenFOAM, compiled extensions) are set up by tools/setup_engines.sh,
# which this script calls when it exists and when --engines is given.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top"

want_engines=0
for arg in "$@"; do
    case "$arg" in
        --engines) want_engines=1 ;;
        *) echo "setup.sh: unknown option '$arg' (known: --engines)" >&2; exit 2 ;;
    esac
done

python=${PYTHON:-python3}
stamp=.venv/.collheat-stamp
want=$(cat pyproject.toml | sha256sum | cut -d' ' -f1)
if [ ! -x .venv/bin/python ] || [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
    echo "setup: creating the Python environment in .venv (numpy, scipy, matplotlib, meshio, pyvista, foamlib, pytest)"
    "$python" -m venv .venv
    .venv/bin/python -m pip install --quiet --upgrade pip
    .venv/bin/python -m pip install --quiet -e ".[test]"
    echo "$want" > "$stamp"
fi

if [ "$want_engines" = 1 ] && [ -x tools/setup_engines.sh ]; then
    tools/setup_engines.sh
fi
