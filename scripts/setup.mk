# The set-up rules, shared by the course's Makefile and the student
# repository's (grading/templates/Makefile): the system packages, then a
# .venv with the pinned requirements and this package.
#   PYTHON        the interpreter to build .venv with (Python 3.11 or newer)
#   REQUIREMENTS  the pinned set (the course's full lock; students: their subset)
#   SYSTEM_DEPS   what scripts/system-deps.sh provides: grading, book, build, browser
PYTHON       ?= python3
REQUIREMENTS ?= requirements/course.txt
SYSTEM_DEPS  ?= grading book build browser
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.setup-done

.PHONY: setup

setup: $(STAMP)

# A .venv left by a failed or older set-up, built with an interpreter below
# the floor, is rebuilt rather than reused.
$(STAMP): $(REQUIREMENTS) pyproject.toml scripts/system-deps.sh scripts/setup.mk scripts/check_python.py
	PYTHON=$(PYTHON) bash scripts/system-deps.sh $(SYSTEM_DEPS)
	@$(PYTHON) scripts/check_python.py
	@if [ -e $(VENV) ] && ! $(BIN)/python scripts/check_python.py 2>/dev/null; then \
	    echo "Rebuilding $(VENV): it was made by an unsupported or missing Python"; rm -rf $(VENV); fi
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -r $(REQUIREMENTS)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check --no-deps -e .
	$(BIN)/python -c "import numpy, scipy, sklearn, numba, pytest"
	touch $@
