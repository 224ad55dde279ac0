# The two commands of the README: `make demo` and `make test`; `make docs` builds the docs site into site/.
# Both build .venv from scratch on a machine with only Python >= 3.10 and make.
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip --disable-pip-version-check -q
DEMO_OUT ?= demo-output

.PHONY: demo test docs clean

$(VENV)/.base: pyproject.toml
	$(PYTHON) -c 'import sys; sys.exit("tribokin needs Python >= 3.10, found " + sys.version.split()[0]) if sys.version_info < (3, 10) else None'
	$(PYTHON) -m venv $(VENV)
	$(PIP) install -e .
	@echo "compiling tribokin's numba kernels into their cache (once, about a minute: tools/compile_kernels.py)"
	$(PY) tools/compile_kernels.py
	touch $@

$(VENV)/.test: $(VENV)/.base
	$(PIP) install -e '.[test]'
	touch $@

$(VENV)/.docs: $(VENV)/.base
	$(PIP) install -e '.[docs]'
	touch $@

DEMO_STUDIES := paper-fig10-frictionless paper-fig11-constant paper-fig12-gaussian paper-fig13-uniform \
                tribology-log tribology-surfaces \
                gantry-iso ur5-iso panda-iso ur5-published ur10-published panda-published ur5-warm-up two-link-xacro \
                gantry-map ur5-map-horizontal ur5-map-directional panda-map-vertical ur5-what-if-materials \
                what-if-robots what-if-placement gantry-placement ur5-placement

demo: $(VENV)/.base
	@mkdir -p $(DEMO_OUT)
	@for study in $(DEMO_STUDIES); do \
		echo "== $$study"; \
		$(VENV)/bin/tribokin run studies/$$study.toml --out $(DEMO_OUT)/$$study --force || exit $$?; \
	done
	@echo "== measured and calibrated: synthetic UR5 tracker data (studies/data/ur5-tracker.csv)"
	$(VENV)/bin/tribokin measure studies/data/ur5-tracker.csv --out $(DEMO_OUT)/ur5-measured --force
	$(VENV)/bin/tribokin calibrate studies/ur5-calibrate.toml --measurements studies/data/ur5-tracker.csv \
		--out $(DEMO_OUT)/ur5-fit --force
	$(VENV)/bin/tribokin run $(DEMO_OUT)/ur5-fit/calibrated.toml --out $(DEMO_OUT)/ur5-predicted --force
	@echo "== measured and calibrated: the IPA UR10 laser-tracker data (studies/data/ipa-ur10, MIT)"
	$(PY) tools/ipa_series_d.py studies/data/ipa-ur10 --out $(DEMO_OUT)/ipa-ur10-series-d.csv --force >/dev/null
	$(VENV)/bin/tribokin measure $(DEMO_OUT)/ipa-ur10-series-d.csv --out $(DEMO_OUT)/ipa-measured --force
	$(VENV)/bin/tribokin calibrate studies/ur10-ipa-calibrate.toml --measurements $(DEMO_OUT)/ipa-ur10-series-d.csv \
		--out $(DEMO_OUT)/ipa-fit --force
	@echo "demo results: $(DEMO_OUT)/<study>/ (summary.json, poses.csv, field_*.png, report.html; maps: map*.csv, map_*.png)"
	@for study in $(DEMO_STUDIES) ur5-measured ur5-fit ur5-predicted ipa-measured ipa-fit; do \
		if [ -f $(DEMO_OUT)/$$study/report.html ]; then echo "report: $(DEMO_OUT)/$$study/report.html"; fi; done
	@echo "tribokin is in $(VENV), not on your PATH: run $(VENV)/bin/tribokin, or first source $(VENV)/bin/activate"

# Python's bytecode caches are written even where PYTHONDONTWRITEBYTECODE is set: every command and worker process the
# suite starts would otherwise compile tribokin's modules again, and every pytest worker rewrite each test module.
test: $(VENV)/.test
	PYTHONDONTWRITEBYTECODE= $(PY) -m pytest -q -n auto --dist loadgroup

# The docs site (mkdocs.yml): the study-file reference regenerated first, then built in strict mode (a broken
# link, a docstring mkdocstrings cannot read or a page missing from the nav fails the build).
docs: $(VENV)/.docs
	$(PY) tools/study_reference.py
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict --site-dir site

clean:
	rm -rf $(VENV) $(DEMO_OUT) site
