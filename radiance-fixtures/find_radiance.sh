# Sourced by the fixture scripts: puts real Radiance's bin/ first on PATH and sets RAYPATH.
# RADIANCE_BIN (and optionally RAYPATH) choose an install; otherwise pip's pyradiance.
# Usage: source find_radiance.sh NEEDED_PROGRAM SCRIPT_NAME
if [[ -n "${RADIANCE_BIN:-}" ]]; then
	RBIN=$RADIANCE_BIN
	RLIB=${RAYPATH:-$(dirname "$RBIN")/lib}
else
	ROOT=$(python3 -c "import pyradiance, os; print(os.path.dirname(pyradiance.__file__))")
	RBIN=$ROOT/bin
	RLIB=$ROOT/lib
fi
[[ -x $RBIN/$1 ]] || { echo "$2: no $1 in $RBIN" >&2; exit 1; }
export PATH="$RBIN:$PATH"
export RAYPATH=".:$RLIB"
