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
venv_ok=1
[ -x .venv/bin/python ] && [ "$(cat "$stamp" 2>/dev/null)" = "$want" ] || venv_ok=0

# The engines (Debian packages, compiled solver and helper) build while pip installs: on a
# fresh machine each takes about a minute and they share nothing but the cores.
engines_pid=""
engines_log=$top/.setup-engines.log
if [ "$want_engines" = 1 ] && [ -x tools/setup_engines.sh ]; then
    if [ "$venv_ok" = 1 ]; then
        tools/setup_engines.sh
    else
        echo "setup: building the engines' part meanwhile (log: $engines_log)"
        tools/setup_engines.sh > "$engines_log" 2>&1 &
        engines_pid=$!
    fi
fi

if [ "$venv_ok" = 0 ]; then
    echo "setup: creating the Python environment in .venv (numpy, scipy, matplotlib, meshio, pyvista, foamlib, pytest)"
    "$python" -m venv .venv
    .venv/bin/python -m pip install --quiet --upgrade pip
    .venv/bin/python -m pip install --quiet -e ".[test]"
    echo "$want" > "$stamp"
fi

if [ -n "$engines_pid" ]; then
    status=0
    wait "$engines_pid" || status=$?
    cat "$engines_log"
    [ "$status" = 0 ] || { echo "setup: the engines' set-up failed (exit $status; its log above)" >&2; exit "$status"; }
    rm -f "$engines_log"
fi

# The project's own modules compiled to bytecode once: where PYTHONDONTWRITEBYTECODE is set
# (this machine), Python would otherwise compile its ~100 modules at every run's start
# (about 0.2 s). A source changed since is compiled again at import, as always.
.venv/bin/python -m compileall -q pyhost plugins tools > /dev/null || true

if [ "$want_engines" = 1 ]; then
    # mpi4py for the host under mpirun: Debian's, built against the same OpenMPI as LIGGGHTS
    # (a PyPI wheel may bring another MPI). Only that package is linked into .venv.
    site=$(.venv/bin/python -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
    [ -e "$site/mpi4py" ] || ln -s /usr/lib/python3/dist-packages/mpi4py "$site/mpi4py"
fi
