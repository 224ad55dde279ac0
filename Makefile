# The two commands of the README: `make demo` and `make test`.
# Both build .venv from scratch on a machine with only Python >= 3.10 and make.
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip --disable-pip-version-check -q
DEMO_OUT ?= demo-output

.PHONY: demo test clean

$(VENV)/.base: pyproject.toml
	$(PYTHON) -c 'import sys; sys.exit("tribokin needs Python >= 3.10, found " + sys.version.split()[0]) if sys.version_info < (3, 10) else None'
	$(PYTHON) -m venv $(VENV)
	$(PIP) install -e .
	touch $@

$(VENV)/.test: $(VENV)/.base
	$(PIP) install -e '.[test]'
	touch $@

DEMO_STUDIES := paper-fig10-frictionless paper-fig11-constant paper-fig12-gaussian paper-fig13-uniform \
                tribology-log tribology-surfaces \
                gantry-iso ur5-iso panda-iso gantry-map ur5-map-horizontal panda-map-vertical ur5-what-if-materials

demo: $(VENV)/.base
	@mkdir -p $(DEMO_OUT)
	@for study in $(DEMO_STUDIES); do \
		echo "== $$study"; \
		$(VENV)/bin/tribokin run studies/$$study.toml --out $(DEMO_OUT)/$$study --force || exit $$?; \
	done
	@echo "demo results: $(DEMO_OUT)/<study>/ (summary.json, poses.csv, field_*.png, report.html; maps: map*.csv, map_*.png)"
	@for study in $(DEMO_STUDIES); do echo "report: $(DEMO_OUT)/$$study/report.html"; done
	@echo "tribokin is in $(VENV), not on your PATH: run $(VENV)/bin/tribokin, or first source $(VENV)/bin/activate"

test: $(VENV)/.test
	$(PY) -m pytest -q

clean:
	rm -rf $(VENV) $(DEMO_OUT)
