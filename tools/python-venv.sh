# Sourced by the Python test drivers: creates (or reuses) the virtual environment
# $root/.venv and sets $venv. Needs $root. Works on a fresh Debian machine, where
# `python3 -m venv` may be missing (python3-venv): it then falls back to virtualenv.
python="${PYTHON:-python3}"
venv="$root/.venv"
if [[ ! -x "$venv/bin/python" ]]; then
    echo "python-venv: creating $venv"
    if ! "$python" -m venv "$venv" 2>/dev/null; then
        rm -rf "$venv"
        echo "python-venv: '$python -m venv' is unavailable; using virtualenv"
        "$python" -m pip install --quiet --user virtualenv \
            || "$python" -m pip install --quiet --user --break-system-packages virtualenv
        "$python" -m virtualenv --quiet "$venv"
    fi
fi
