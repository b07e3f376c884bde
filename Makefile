# Toppling columns: `make run-all` runs the main job, `make test` the tests.
# Every target depends on `setup`, which installs YADE (apt-get) and .venv when missing.
SHELL := /bin/bash
PY := .venv/bin/python
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
JOBS ?= $(shell nproc)

.PHONY: setup test run-all records campaigns bench clean invert-demo shake-table rock-fragility rock-survival docs \
	convergence paper-question invert-study invert-study-table contact-convergence \
	shake-table-scores shake-table-scores-quick field-rock oq-case-mrd oq-hazard-job

setup: .venv/.installed
	@command -v yade >/dev/null || { echo "installing YADE (apt-get install yade)"; \
	  $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get update -qq && \
	  $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq yade; }

.venv/.installed: pyproject.toml
	test -x $(PY) || python3 -m venv .venv
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[test]'
	touch $@

# the layers of the stages (import-linter contract in pyproject.toml), ruff, the YADE physics
# tests on glibc's second libm path (another CPU's last bits), then all; on every core
# (pytest-xdist, a test file per worker at a time: its module fixtures are made once;
# as many workers as nproc says, not xdist's "auto", which counts physical cores only)
TEST_WORKERS ?= $(JOBS)
test: setup
	.venv/bin/lint-imports
	$(PY) -m ruff check pipeline tests bench yade_scripts
	$(PY) -m pytest -q -n $(TEST_WORKERS) --dist loadfile -m libm --second-libm tests
	$(PY) -m pytest -q -n $(TEST_WORKERS) --dist loadfile tests

records: setup
	$(PY) -m pipeline records --all

# run-all: the paper's campaigns at full size, then every REPORT.md section; the
# paper's question, fragility and the inversion at a reduced size (the REPORT says what
# was reduced; make paper-question, make invert-demo and campaign fragility give them
# in full).  The ensembles' nominal runs are the records campaign's (copied, not rerun).
PAPER_BATCH ?= 1
FRAGILITY_LEVELS := 1,2,4,8
# the colonnade (reduced): the shipped stretch of the Parthenon's north flank
# (docs/colonnades.md), one run per record at its columns' matched contact stiffness:
# 58 bodies stepping 7.5e-5 s, about 6.5 s of one core per simulated second (NF04: 26 s
# simulated, 2.8 min of one core), about 5-10 min on 2 idle cores for the three
COLONNADE := parthenon-north-flank
COLONNADE_RECORDS ?= NF04,RSN181-IMPVALL,RSN126-GAZLI
# the same colonnade shaken along its row, across it and at 45 deg by one one-cosine pulse
# (0.3 g, PGV/PGA 0.3 s: just below the smallest amplitude that overturns a rigid cylinder
# of the column's height and base diameter, 0.31 g, and the rigid in-plane frame of the
# colonnade's beam-to-column mass ratio 0.52, 0.35 g), one run per direction
# (docs/colonnades.md).  A run whose columns all fell took 134 s of one core (15.9 s
# simulated): about 5-7 min of one core for the three
COLONNADE_DIRECTIONS_PULSES ?= pga_g=0.3:0.3:1;pgv_pga_s=0.3:0.3:1
STEP_TIMES := results/run-all-steps.tsv
# $(call timed,NAME,COMMAND): run COMMAND, append NAME and its wall seconds to STEP_TIMES
define timed
@s=$$(date +%s.%N); $(2); rc=$$?; e=$$(date +%s.%N); \
  awk -v n='$(subst ','\'',$(1))' -v s=$$s -v e=$$e -v rc=$$rc 'BEGIN{printf "%s\t%.1f\t%d\n", n, e - s, rc}' \
  >> $(STEP_TIMES); exit $$rc
endef

campaigns: setup
	@mkdir -p results && printf 'step\twall_s\texit\n' > $(STEP_TIMES)
	$(call timed,records,$(PY) -m pipeline records --all)
	$(call timed,verification,$(PY) -m pipeline campaign verification --jobs $(JOBS))
	$(call timed,slenderness,$(PY) -m pipeline campaign slenderness --jobs $(JOBS))
	$(call timed,friction,$(PY) -m pipeline campaign friction --jobs $(JOBS))
	$(call timed,records campaign,$(PY) -m pipeline campaign records --jobs $(JOBS))
	$(call timed,synthetic,$(PY) -m pipeline campaign synthetic --jobs $(JOBS))
	$(call timed,paper question (reduced),$(PY) -m pipeline campaign ensemble --set nearsource \
	  --out results/paper-question --members $(PAPER_BATCH) --max-members $(PAPER_BATCH) \
	  --animations 0 --jobs $(JOBS))
	$(call timed,real columns,$(PY) -m pipeline campaign columns --jobs $(JOBS))
	$(call timed,fragility (reduced),$(PY) -m pipeline campaign fragility \
	  --levels $(FRAGILITY_LEVELS) --members 1 --jobs $(JOBS))
	$(call timed,colonnade (reduced),$(PY) -m pipeline campaign records \
	  --column-file $(COLONNADE) --records $(COLONNADE_RECORDS) --out results/colonnade \
	  --animations 0 --jobs $(JOBS))
	$(call timed,colonnade directions (reduced),$(PY) -m pipeline campaign colonnade-directions \
	  --pulses "$(COLONNADE_DIRECTIONS_PULSES)" --out results/colonnade-directions \
	  --animations 0 --jobs $(JOBS))
	$(call timed,inversion demo (quick),$(PY) -m pipeline invert --demo --quick --jobs $(JOBS))
	$(call timed,field rock fragility (reduced),$(PY) -m pipeline campaign fragility \
	  --column-file $(FIELD_ROCK) --pulses "$(FIELD_ROCK_QUICK_PULSES)" --adaptive --animations 0 \
	  --out results/field-rock-quick-fragility --jobs $(JOBS))
	$(call timed,field rock survival (reduced),$(PY) -m pipeline survival \
	  $(FIELD_ROCK_SURVIVAL_HAZARD) --fragility results/field-rock-quick-fragility/fragility.json \
	  $(FIELD_ROCK_SITE) --out results/field-rock-quick-survival)
	$(call timed,field rock constrained hazard (reduced),$(PY) -m pipeline constrain \
	  --logic-tree $(FIELD_ROCK_TREE) --fragility results/field-rock-quick-fragility/fragility.json \
	  $(FIELD_ROCK_SITE) --out results/field-rock-quick-constrain)
	$(call timed,field rock survival at correlation 0.733 (reduced),$(PY) -m pipeline survival \
	  $(FIELD_ROCK_SURVIVAL_HAZARD) --fragility results/field-rock-quick-fragility/fragility.json \
	  $(FIELD_ROCK_SITE) --pga-pgv-correlation 0.733 --out results/field-rock-quick-survival-bradley2012)
	$(call timed,hazard routes (Double Rock at an OpenQuake QA site),$(HAZARD_ROUTES))
	$(call timed,shake-table scores (reduced),$(PY) -m pipeline campaign shake-table --members 4 \
	  --tests $(SCORES_QUICK_TESTS) --candidates "$(SCORES_QUICK_CANDIDATES)" \
	  --out results/shake-table-scores-quick --animations 0 \
	  --jobs $(JOBS))

# the routes to the joint hazard of PGA and PGV on one site (the OpenQuake QA case
# postproc/case_mrd shipped in records/hazard/), with Double Rock's reduced fragility:
# survival under (a) the mean rate density, (b) the PGA curve with its Mag_Dist
# disaggregation, (c) the PGA curve with one scenario (M 5.75, 110 km: the modal bin of
# that disaggregation at 0.0062 g; the site's Vs30 1000 m/s), and constrain under each
# (route b per realisation: each branch its own Mag_Dist column); 100 fragility draws.
# About 1 min on 2 cores
ROUTES_CASE := records/hazard/openquake_postproc_case_mrd
ROUTES_ROCK := --fragility results/field-rock-quick-fragility/fragility.json --age-ka 15 \
  --age-sd-ka 3 --draws 100
ROUTES_SCENARIO := --magnitude 5.75 --distance-km 110 --vs30 1000
ROUTES_OUT := results/hazard-routes
HAZARD_ROUTES := $(PY) -m pipeline survival --joint-hazard $(ROUTES_CASE)/mrd_pga_pgv.hdf5 \
  $(ROUTES_ROCK) --out $(ROUTES_OUT)/joint-survival && \
  $(PY) -m pipeline survival --hazard $(ROUTES_CASE)/hazard_curve-mean-PGA_6.csv \
  --disaggregation $(ROUTES_CASE)/disaggregation/Mag_Dist-mean-0_7.csv --vs30 1000 \
  $(ROUTES_ROCK) --out $(ROUTES_OUT)/disaggregation-survival && \
  $(PY) -m pipeline survival --hazard $(ROUTES_CASE)/hazard_curve-mean-PGA_6.csv \
  $(ROUTES_SCENARIO) $(ROUTES_ROCK) --out $(ROUTES_OUT)/scenario-survival && \
  $(PY) -m pipeline constrain --logic-tree $(ROUTES_CASE) --joint-hazard \
  $(ROUTES_CASE)/mrd_pga_pgv.hdf5 $(ROUTES_ROCK) --out $(ROUTES_OUT)/joint-constrain && \
  $(PY) -m pipeline constrain --logic-tree $(ROUTES_CASE) --disaggregation \
  $(ROUTES_CASE)/disaggregation/Mag_Dist-0_7.csv --vs30 1000 $(ROUTES_ROCK) \
  --out $(ROUTES_OUT)/disaggregation-constrain && \
  $(PY) -m pipeline constrain --logic-tree $(ROUTES_CASE) $(ROUTES_SCENARIO) $(ROUTES_ROCK) \
  --out $(ROUTES_OUT)/scenario-constrain

run-all: campaigns
	$(PY) -m pipeline report

bench: setup
	@$(PY) -c "import mujoco" 2>/dev/null || $(PY) -m pip install -q -e '.[bench]'
	$(PY) bench/bench_yade.py

# the scanned granite rock SP1 against 490 shake-table tests (calibrate June-July 2021,
# validate August; 16 parameter sets over footprint, damping, friction and the axis's
# sign): about 1 h on 2 cores
shake-table: setup
	$(PY) -m pipeline campaign shake-table $(if $(SHAKE_GRID),--grid "$(SHAKE_GRID)") --jobs $(JOBS) \
	  --allow-long
	$(PY) -m pipeline report

# each shake-table test of SP1 predicted by the fragility's members (its draws and seed),
# scored as probabilities per split beside the calibration's single set, the baselines and
# the providers' models of SP1.  The members' ranges are chosen first on the June-July
# tests alone, out of sample over their days: each of SCORES_CANDIDATES (the declared
# defaults, pipeline/campaign/member_ranges.py; without the yaw; a wider yaw; the wider
# footprint; wider friction; all three wider) runs there, the June-July days are cut into
# 4 blocks (--folds) and the candidate whose worst block scores best by log-likelihood
# wins, each block checked with the choice made without it (folds.csv,
# shake_table_folds_reliability.png); frozen, it is then run on the August tests.  At most
# 8 members a test (a test stops once its first 4 agree); about 3.5 h on 2 cores (at most
# 14,770 runs, 10.7 core-h; runs stopped early take about 0.6 of that).  The quick one: 24
# tests (12 June-July, 12 August, spread over PGA), 4 members, two candidates, minutes.
# SCORES_RANGES="..." scores one set of ranges instead of choosing.
SCORES_MEMBERS ?= 8
SCORES_RANGES ?=
SCORES_CANDIDATES ?= default|yaw_deg=0:0|yaw_deg=-20:20|footprint_tolerance_m=0.001:0.003|mu_s=0.4:0.9|footprint_tolerance_m=0.001:0.003;mu_s=0.4:0.9;yaw_deg=-20:20
SCORES_QUICK_CANDIDATES := default|footprint_tolerance_m=0.001:0.003;mu_s=0.4:0.9;yaw_deg=-20:20
SCORES_QUICK_TESTS := Test323,Test382,Test379,Test044,Test372,Test273,Test283,Test075,Test091,Test316,Test131,Test178,Test693,Test702,Test473,Test442,Test445,Test594,Test609,Test626,Test540,Test548,Test646,Test566
shake-table-scores: setup
	$(PY) -m pipeline campaign shake-table --members $(SCORES_MEMBERS) \
	  $(if $(SCORES_RANGES),--ranges "$(SCORES_RANGES)",--candidates "$(SCORES_CANDIDATES)") \
	  --out results/shake-table-scores \
	  --animations 0 --jobs $(JOBS) --allow-long

shake-table-scores-quick: setup
	$(PY) -m pipeline campaign shake-table --members 4 --tests $(SCORES_QUICK_TESTS) \
	  $(if $(SCORES_RANGES),--ranges "$(SCORES_RANGES)",--candidates "$(SCORES_QUICK_CANDIDATES)") \
	  --out results/shake-table-scores-quick \
	  --animations 0 --jobs $(JOBS)

# the contact stiffness alone, kn x1, x3, x10, side by side in
# results/contact-convergence/convergence.json: the rock SP1's predictions at the
# calibrated footprint, damping, friction and sign on 27 fixed June-July tests (13 of PGA < 0.15 g,
# 14 from 0.15 g; every 8th and 12th by name); the twin model's ensembles of
# CONTACT_MEMBERS members on CONTACT_RECORD (the same sampled members at every factor;
# CONTACT_MEMBERS=32 for intervals half as wide); Housner free rocking of the paper's
# marble block and monolithic column, and of the rock (its restitution per damping ratio).
# About 15 min on 2 cores (8 members)
CONTACT_TESTS := Test011,Test019,Test034,Test051,Test259,Test318,Test330,Test339,Test350,Test371,Test383,Test397,Test408,Test027,Test060,Test087,Test101,Test117,Test135,Test167,Test183,Test201,Test227,Test241,Test284,Test304,Test361
CONTACT_GRID := footprint_tolerance_m=0.001;damping=0.1;mu_s=0.7;rotate_deg=0;kn=1.2e8,3.6e8,1.2e9
CONTACT_RECORD ?= RC-CLC
CONTACT_MEMBERS ?= 8
CONTACT_FACTORS := 1 3 10
contact-convergence: setup
	$(PY) -m pipeline campaign shake-table --tests $(CONTACT_TESTS) --grid "$(CONTACT_GRID)" \
	  --out results/contact-convergence --animations 0 --jobs $(JOBS)
	for f in $(CONTACT_FACTORS); do \
	  $(PY) -m pipeline campaign ensemble --record $(CONTACT_RECORD) --members $(CONTACT_MEMBERS) \
	    --max-members $(CONTACT_MEMBERS) --vary kn_factor=$$f,$$f --animations 0 \
	    --out results/contact-convergence/twin-x$$f --jobs $(JOBS) || exit 1; done
	$(PY) -m pipeline.campaign.contact_convergence results/contact-convergence --free-rocking
	$(PY) -m pipeline report

# the scanned rock SP1's fragility: over the Virtual Shake Robot's pulse grid (PGA 0.2-1.1 g x
# PGV/PGA 0.1-1.0 s, 10 x 10) from directions sampled over 360 deg, 4 parameter sets x 4
# directions (1,600 runs), and along the table's axis over the range of its shake-table
# tests, checked against them (6 x 4 cells x 4 parameter sets): a few minutes on 2 cores
ROCK_TABLE_PULSES ?= pga_g=0.1:1.0:6;pgv_pga_s=0.02:0.29:4
rock-fragility: setup
	$(PY) -m pipeline campaign fragility --column-file records/shake_table/sp1.json \
	  --pulses vsr --out results/rock-fragility --jobs $(JOBS)
	$(PY) -m pipeline campaign fragility --column-file records/shake_table/sp1.json \
	  --pulses "$(ROCK_TABLE_PULSES)" --members 4 --azimuth 90 \
	  --out results/rock-fragility-table --jobs $(JOBS)
	$(PY) -m pipeline report

# SP1's pulse-grid fragility (the first campaign of rock-fragility, run only when its
# fragility.json is missing) under the USGS 2014 hazard curve shipped in records/hazard/,
# PGV/PGA from the ground-motion model at M 6.5, 10 km; an age of 15 +- 3 ka
ROCK_SURVIVAL_HAZARD ?= records/hazard/usgs_nshm2014r1_curves_-118_34_vs760.json
rock-survival: results/rock-fragility/fragility.json
	$(PY) -m pipeline survival --hazard $(ROCK_SURVIVAL_HAZARD) \
	  --fragility results/rock-fragility/fragility.json --magnitude 6.5 --distance-km 10 \
	  --age-ka 15 --age-sd-ka 3 --out results/rock-survival
	$(PY) -m pipeline report

results/rock-fragility/fragility.json: | setup
	$(PY) -m pipeline campaign fragility --column-file records/shake_table/sp1.json \
	  --pulses vsr --out results/rock-fragility --jobs $(JOBS)

# the field rock Double Rock (records/field_rocks/double_rock/, the Virtual Shake Robot's
# mesh): its fragility over pulses from directions sampled over 360 deg (the field default:
# 4 parameter sets x 4 directions, adaptive), on a grid from 0.05 g that holds its P = 0.5
# contour (it lies at 0.15-0.35 g); its survival under the mean and 0.1 / 0.9 quantile
# curves of OpenQuake's logic-tree QA case 19 (SHARE's settings: 16 ground-motion branches,
# PGA from 0.0137 g, records/hazard/openquake_logictree_case_19/) and that logic tree
# constrained by it. The hazard is illustrative (the engine's test input at a site in
# Calabria, not Arizona's); the age (15 +- 3 ka) is an assumption of the demonstration, the
# PGV/PGA Boore et al. 2014 at M 6.5, 55 km, Vs30 800 m/s: the modal bin of the case's own
# disaggregation at 0.2 g (its in-slab source 50 km under the site) and its Vs30. About
# 10 min on 2 cores (706 runs of the full grid's 3,520); run-all runs the three on a coarser
# grid (FIELD_ROCK_QUICK_PULSES, 6 x 4 cells, the same 4 parameter sets x 4 directions):
# about 1 min
FIELD_ROCK := records/field_rocks/double_rock/double_rock.json
FIELD_ROCK_PULSES ?= pga_g=0.05:1.1:22;pgv_pga_s=0.1:1.0:10
FIELD_ROCK_QUICK_PULSES ?= pga_g=0.05:0.8:6;pgv_pga_s=0.1:1.0:4
FIELD_ROCK_TREE := records/hazard/openquake_logictree_case_19
FIELD_ROCK_SURVIVAL_HAZARD := --hazard $(FIELD_ROCK_TREE)/hazard_curve-mean-PGA_13.csv \
  --hazard $(FIELD_ROCK_TREE)/quantile_curve-0.1-PGA_13.csv \
  --hazard $(FIELD_ROCK_TREE)/quantile_curve-0.9-PGA_13.csv
FIELD_ROCK_SITE := --magnitude 6.5 --distance-km 55 --vs30 800 --age-ka 15 --age-sd-ka 3
field-rock: setup
	$(PY) -m pipeline campaign fragility --column-file $(FIELD_ROCK) --pulses "$(FIELD_ROCK_PULSES)" \
	  --adaptive --out results/field-rock-fragility --jobs $(JOBS)
	$(PY) -m pipeline survival $(FIELD_ROCK_SURVIVAL_HAZARD) \
	  --fragility results/field-rock-fragility/fragility.json $(FIELD_ROCK_SITE) \
	  --out results/field-rock-survival
	$(PY) -m pipeline constrain --logic-tree $(FIELD_ROCK_TREE) \
	  --fragility results/field-rock-fragility/fragility.json $(FIELD_ROCK_SITE) \
	  --out results/field-rock-constrain
	$(PY) -m pipeline report

# the model's convergence judged on distributions: the twin model's ensembles of 3 records
# at 16 (default), 32 and 64 rim points and time step factor 0.15, 32 members each
convergence: records
	$(PY) -m pipeline campaign convergence --jobs $(JOBS) --allow-long
	$(PY) -m pipeline report

# the paper's question at full precision: every near-source record's ensemble sized by its
# error (P(toppled) within +-0.1, falls' mean direction within 60 deg), pooled over records;
# it takes over the reduced ensembles of run-all (the same first members) and adds batches
paper-question: records
	$(PY) -m pipeline campaign ensemble --set nearsource --out results/paper-question \
	  --members $(PAPER_BATCH) --jobs $(JOBS) --allow-long
	$(PY) -m pipeline report

# the docs/ tree as a website (results/site; mkdocs --strict fails on a broken link)
docs: setup
	@$(PY) -c "import mkdocs, mkdocs_macros" 2>/dev/null || $(PY) -m pip install -q -e '.[docs]'
	$(PY) -m mkdocs build --quiet

invert-demo: setup
	$(PY) -m pipeline invert --demo --grid $(or $(INVERT_GRID),demo) --jobs $(JOBS) --allow-long $(INVERT_ARGS)
	$(PY) -m pipeline report

# how many fallen columns bound the source: truth tests at 3-48 likelihood members per node
# on the study grid's forward table, the one shipped in records/inversion/ (the study
# alone, tens of minutes on 2 cores); invert-study-table computes the table itself first (3,072 YADE runs,
# hours on 2 cores; finished runs are kept when interrupted)
STUDY_TABLE := records/inversion/forward_table_study.npz
invert-study: setup
	$(PY) -m pipeline invert --member-study --jobs $(JOBS) \
	  $(if $(wildcard $(STUDY_TABLE)),--table $(STUDY_TABLE),--allow-long) $(INVERT_ARGS)
	$(PY) -m pipeline report

invert-study-table: setup
	$(PY) -m pipeline invert --member-study --jobs $(JOBS) --allow-long $(INVERT_ARGS)
	$(PY) -m pipeline report

# The OpenQuake engine on its small QA case postproc/case_mrd (the data shipped in
# records/hazard/openquake_postproc_case_mrd, computed again into results/oq_case_mrd),
# stating the engine's wall time of each step.  The engine is an optional extra with pins
# of its own: it goes into an environment of its own, $(OQ_VENV), made when missing
# (records/tools/oq_engine_requirements.txt: its requirements but GDAL, which has no wheel).
# oq-hazard-job: the same case from its job.ini to the constrained hazard in one command
# (pipeline hazard-job; a test input, not the hazard at that place, and an illustrative
# rock), stating the engine's wall time of each step.
OQ_VENV ?= .venv-oq
$(OQ_VENV)/.installed:
	@echo "installing the OpenQuake engine into $(OQ_VENV)"
	test -x $(OQ_VENV)/bin/python || python3 -m venv $(OQ_VENV)
	$(OQ_VENV)/bin/pip install -q -r records/tools/oq_engine_requirements.txt
	$(OQ_VENV)/bin/pip install -q --no-deps openquake-engine==3.26.2
	touch $@

oq-case-mrd: $(OQ_VENV)/.installed
	records/tools/run_oq_case_mrd.sh $(OQ_VENV)/bin/python results/oq_case_mrd

oq-hazard-job: setup $(OQ_VENV)/.installed
	$(PY) -m pipeline hazard-job --oq-job records/hazard/openquake_postproc_case_mrd/input/job.ini \
	  --oq-python $(OQ_VENV)/bin/python --oq-site 11.202 42.424 \
	  --median-g 0.01 --beta 0.5 --age-ka 10 --age-sd-ka 1 --out results/oq_hazard_job

clean:
	rm -rf results/*/ results/REPORT.md
