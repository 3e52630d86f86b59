#!/usr/bin/env bash
# Set up what is missing, then run one job:  bash tools/dev.sh {setup|demo|test|selftest|bench} [args...]
# Idempotent: Debian packages are installed only when absent; the virtual environment at .venv is
# created once and reinstalled only when pyproject.toml or requirements/pinned.txt change.
set -euo pipefail
cd "$(dirname "$0")/.."

job="${1:-setup}"
shift || true

# OpenGL on the CPU (Mesa llvmpipe): EGL for VTK and moderngl, OSMesa as VTK's fallback window; Xvfb (and xauth,
# which xvfb-run needs) for the test of the interactive window on a virtual display; chromium (headless) loads the
# page of the Jupyter 'server' backend in its test.
DEB_PACKAGES=(libegl1 libegl-mesa0 libgl1-mesa-dri libgl1 libosmesa6 xvfb xauth chromium)
PY="${PYTHON:-python3}"

as_root() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }

setup_system() {
    local missing=()
    for p in "${DEB_PACKAGES[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
    if ! "$PY" -c "import venv, ensurepip" 2>/dev/null; then missing+=(python3-venv); fi
    if [ "${#missing[@]}" -gt 0 ]; then
        echo "[splinevis] installing Debian packages: ${missing[*]}"
        as_root apt-get update -qq
        DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
    fi
}

setup_python() {
    "$PY" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else 1)' || {
        echo "[splinevis] Python >= 3.11 is required; $PY is $("$PY" --version 2>&1). Set PYTHON=/path/to/python3.11." >&2
        exit 1
    }
    [ -x .venv/bin/python ] || { echo "[splinevis] creating .venv"; "$PY" -m venv .venv; }
    local stamp=.venv/.splinevis-stamp
    local want
    want="$(cat pyproject.toml requirements/pinned.txt | sha256sum | cut -d' ' -f1)"
    if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
        echo "[splinevis] installing splinevis (editable) and its pinned dependencies into .venv"
        .venv/bin/python -m pip install -q --upgrade pip
        .venv/bin/python -m pip install -q -c requirements/pinned.txt -e ".[test,all]"
        echo "$want" > "$stamp"
    fi
}

setup_system
setup_python

case "$job" in
    setup) ;;
    demo) .venv/bin/splinevis demo --out "${1:-out}" ;;
    selftest) .venv/bin/splinevis selftest --out "${1:-out}" ;;
    bench) .venv/bin/python benchmarks/run.py "$@" ;;
    test)
        # two pytest workers (pytest-xdist): most tests run one core (the float64 twins, numpy), so the suite
        # takes about half the time on the 2-core CI machine. Each file goes to one worker (--dist loadfile), so a
        # module's fixtures (built LOD models, a study's quick run) are made once and not on both workers: measured
        # in one fresh clone, one after the other, 9 m 54 s and 17.5 CPU-minutes against 10 m 37 s and 19.2 with
        # work stealing. Arguments are passed on to pytest.
        # one BLAS/OpenMP thread per worker unless the caller sets it: two workers with two BLAS threads each
        # would oversubscribe the two cores (stored numbers do not depend on it: tests/test_generated_machine_independent.py)
        export OPENBLAS_NUM_THREADS="${OPENBLAS_NUM_THREADS:-1}" OMP_NUM_THREADS="${OMP_NUM_THREADS:-1}"
        set +e
        .venv/bin/python -m pytest -n "${SPLINEVIS_TEST_WORKERS:-2}" --dist loadfile "$@"
        rc=$?
        set -e
        if [ "$rc" -eq 5 ]; then
            echo "[splinevis] pytest collected no tests: the suite is missing or mis-selected; failing." >&2
            exit 1
        fi
        exit "$rc"
        ;;
    check)
        # splinevis check on the real files (../shared/data, or SPLINEVIS_REALDATA): files listed in
        # tests/realdata_known.json may FAIL (each with its measured reason); any other FAIL fails the job, a
        # listed file that passes is printed so that its entry can go
        data="${SPLINEVIS_REALDATA:-../shared/data}"
        if [ ! -d "$data" ]; then
            echo "[splinevis] no real-file folder at $data: splinevis check not run"
            exit 0
        fi
        .venv/bin/splinevis check "$data" --out "${1:-out/check}" --known tests/realdata_known.json --quiet
        ;;
    *) echo "usage: bash tools/dev.sh {setup|demo|test|check|selftest|bench} [args]" >&2; exit 2 ;;
esac
