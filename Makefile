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

.PHONY: all example radiance-example build test radiance fixtures clean

all: example

build:
	$(CARGO) build --release --bins

# The main job: a climate-based daylight study of the example room with the real London
# weather file. Sky matrix (rspecsky, the gendaymtx counterpart) x daylight coefficients
# (rmtx, the dctimestep/rmtxop counterpart) -> illuminance -> annual metrics and maps
# (rmetrics). Until rdc traces rooms (issue 3), the coefficients are real rcontrib's, committed
# in radiance-fixtures/ (-ab 5 -ad 10000, mean of 3 runs); set DC=... to use your own.
DC       ?= $(FIX)/dc/office_m1.mtx
MAPS     := TAI_klxh DA UDI_a sDA

example: build
	@mkdir -p $(OUT)
	$(BIN)/rinfo $(ROOM)/room.rad $(ROOM)/sensors.pts $(EPW)
	$(BIN)/rspecsky -m 1 -of $(EPW) > $(OUT)/sky.smx
	$(BIN)/rmtx -ff -c 47.4 119.9 11.6 $(DC) $(OUT)/sky.smx > $(OUT)/illuminance.mtx
	$(BIN)/rmetrics -w $(EPW) --pts $(ROOM)/sensors.pts --json $(OUT)/metrics.json \
	    -o $(OUT)/metrics.tsv $(OUT)/illuminance.mtx
	@for m in $(MAPS); do \
	    $(BIN)/rmetrics -w $(EPW) --pts $(ROOM)/sensors.pts --map $$m --png $(OUT)/$$m.png \
	        $(OUT)/illuminance.mtx > /dev/null || exit 1; done
	@echo "Room means (occupied 8-18 h, every day), also in $(OUT)/metrics.tsv and .json:"
	@grep -v '^#' $(OUT)/metrics.tsv | head -n 1; grep '^room' $(OUT)/metrics.tsv
	@echo "Maps: $(foreach m,$(MAPS),$(OUT)/$(m).png)"

# The same study with real Radiance (pyradiance): epw2wea, gendaymtx, dctimestep, rmtxop on
# the same coefficients, then both results side by side (seed Appendix A errors).
radiance-example: build radiance
	@mkdir -p $(OUT)/radiance
	@RB=$$($(PYTHON) -c "import pyradiance,os;print(os.path.dirname(pyradiance.__file__))"); \
	export PATH="$$RB/bin:$$PATH" RAYPATH=".:$$RB/lib"; set -e; \
	epw2wea $(EPW) $(OUT)/radiance/site.wea; \
	gendaymtx -m 1 -of $(OUT)/radiance/site.wea > $(OUT)/radiance/sky.smx; \
	dctimestep $(DC) $(OUT)/radiance/sky.smx | rmtxop -ff -c 47.4 119.9 11.6 - > $(OUT)/radiance/illuminance.mtx
	$(BIN)/rmetrics -w $(EPW) -o $(OUT)/radiance/metrics.tsv $(OUT)/radiance/illuminance.mtx
	@echo "ours:    $$(grep '^room' $(OUT)/metrics.tsv)"
	@echo "Radiance: $$(grep '^room' $(OUT)/radiance/metrics.tsv)"
	$(BIN)/rmetrics compare $(OUT)/radiance/metrics.tsv $(OUT)/metrics.tsv

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
