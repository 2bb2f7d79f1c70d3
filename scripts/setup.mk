# The set-up rules, shared by the course's Makefile and the student
# repository's (grading/templates/Makefile): the Debian packages, then a
# .venv with the pinned requirements and this package.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.setup-done

.PHONY: setup

setup: $(STAMP)

$(STAMP): requirements.txt pyproject.toml scripts/system-deps.sh scripts/setup.mk
	bash scripts/system-deps.sh
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -r requirements.txt
	$(BIN)/python -m pip install --quiet --disable-pip-version-check --no-deps -e .
	$(BIN)/python -c "import open3d, numpy, scipy, sklearn"
	touch $@
