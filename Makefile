# rdaylight: Radiance-compatible daylight tools for existing rooms.
#
#   make          the main job on the bundled example room and real London weather file
#   make test     installs what the tests need (real Radiance via pyradiance) and runs all tests
#
# Makefiles are how our users chain Radiance tools; this one is also a worked example.

PYTHON   ?= python3
CARGO    ?= cargo
OUT      ?= out
# Real Radiance 6 for interop tests and reference fixtures (pinned for reproducibility).
PYRADIANCE ?= pyradiance==1.3.1

BIN      := target/release
ROOM     := examples/room
EPW      := examples/weather/GBR_London.Gatwick.037760_IWEC.epw
FIX      := radiance-fixtures

.PHONY: all example build test radiance fixtures fuzz clean

all: example

build:
	$(CARGO) build --release --bins

# The main job at this stage: read the example room, its sensors and the real weather file,
# then turn Radiance's daylight coefficients for that room into illuminance with our matrix
# tool, through every matrix format and back.
example: build
	@mkdir -p $(OUT)
	$(BIN)/rinfo $(ROOM)/room.rad $(ROOM)/sensors.pts $(EPW)
	$(BIN)/rmtx -ff $(FIX)/dc/office_m1.mtx > $(OUT)/dc.float.mtx
	$(BIN)/rmtx -fd $(OUT)/dc.float.mtx > $(OUT)/dc.double.mtx
	$(BIN)/rmtx -fa $(OUT)/dc.double.mtx > $(OUT)/dc.ascii.mtx
	$(BIN)/rmtx -c 47.4 119.9 11.6 $(OUT)/dc.ascii.mtx $(FIX)/sky/london_4days_m1.smx > $(OUT)/illuminance.mtx
	$(BIN)/rinfo --stats $(OUT)/illuminance.mtx

# Installs real Radiance (pyradiance) when missing, then runs every test: unit, format
# round trips, malformed input, and live interop with the real Radiance binaries.
test: radiance
	$(CARGO) test

radiance:
	@$(PYTHON) -c "import pyradiance" 2>/dev/null || $(PYTHON) -m pip install --quiet "$(PYRADIANCE)"

# Regenerate every reference file from real Radiance (minutes of CPU; not part of `test`).
fixtures: radiance
	bash $(FIX)/make_fixtures.sh

clean:
	rm -rf $(OUT)
