# Sourced by the Python test and benchmark drivers after tools/python-venv.sh: builds the
# `gantry` wheel from python/ with maturin (from the venv's requirements) in the cargo
# profile $GANTRY_PROFILE (default `release`; the test command uses `ci`), the profile
# the binary under test is built with, so the two share every compiled dependency, and
# installs it into $venv over any earlier or editable install. Needs $root and $venv.
rm -rf "$root/target/wheels"
"$venv/bin/maturin" build --profile "${GANTRY_PROFILE:-release}" --quiet \
    --manifest-path "$root/python/Cargo.toml" \
    --interpreter "$venv/bin/python" --out "$root/target/wheels"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps \
    "$root"/target/wheels/gantry-*.whl
