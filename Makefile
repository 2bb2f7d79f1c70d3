# 3D Point Cloud Processing: set-up, book, tests and grading.
#   make book     set up, then build the book into _build/html
#   make test     set up, lint, build the book, run the whole test suite
#   make test-images  build Gradescope's image and the README's set-up on Ubuntu 22.04
#                 and Debian 12 from their archives (slow; root; not part of make test)
#   make lint     ruff check and ruff format --check (rules in pyproject.toml)
#   make numba-cache  compile every numba kernel once, plain and bounds-checked (make test does it first)
#   make grade SUBMISSION=dir    grade a student's clone
#   make requirements   re-pin requirements/ (the lock and its two subsets)
#   make bench    time the references against Open3D, scikit-learn and fpsample
#   make gradescope   write the Gradescope autograder archive of ASSIGNMENT (lecture1, lecture2, lecture3)
SUBMISSION ?=
RESULTS ?= results/results.json
ASSIGNMENT ?= lecture1
GRADESCOPE_ZIP ?= _build/gradescope/autograder-$(ASSIGNMENT).zip

include scripts/setup.mk

.PHONY: lint book notebooks numba-cache test test-images grade gradescope bench requirements clean

# The execution cache keys on each page's own code only: when the package code
# the pages run changes, drop the cache (and Sphinx's saved environment, or it
# would not even re-read the pages) so that every page runs again.
CODE_STAMP := _build/.code-stamp
$(CODE_STAMP): $(wildcard pcl_course/*.py solutions/*.py)
	rm -rf _build/.jupyter_cache _build/.doctrees
	mkdir -p _build && touch $@

# numba's on-disk cache checks a kernel's own file only: a kernel that calls
# one from another file of solutions/_fast (rows.py, say) would keep the old
# code after that file changed. Any change there drops the whole cache, and the bounds-checked
# run's (test_kernels.py) too: it kept the old code.
NUMBA_STAMP := _build/.numba-stamp
$(NUMBA_STAMP): $(wildcard solutions/_fast/*.py)
	rm -f solutions/_fast/__pycache__/*.nbi solutions/_fast/__pycache__/*.nbc
	rm -rf $(NUMBA_CHECKED_CACHE)
	mkdir -p _build && touch $@

# -W -n --keep-going: a failing cell (raise_on_error in _config.yml) or a
# broken reference fails the build, and every problem is reported at once.
book: setup $(CODE_STAMP) $(NUMBA_STAMP)
	$(BIN)/jupyter-book build . -W -n --keep-going
	@echo "The book is in _build/html: open $(CURDIR)/_build/html/index.html"

# The chapters as .ipynb (jupytext), for nbval: it runs every cell again,
# independently of the book's execution cache.
notebooks: setup $(NUMBA_STAMP)
	rm -rf _build/notebooks && mkdir -p _build/notebooks
	for page in $$(grep -l '{code-cell}' book/*.md); do \
	    $(BIN)/jupytext --quiet --to ipynb --output _build/notebooks/$$(basename $$page .md).ipynb $$page || exit 1; \
	done

lint: setup
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

# The book's build executes every page whose code is not in its execution cache; nbval runs
# every page again, independently of that cache, when there is one (on a fresh clone, or
# after a change to the package, the build itself runs every page: nbval would only repeat
# it). The build (then the checks of the built book, marker book) and nbval run one page or
# one browser at a time on one core, and many project tests wait on a subprocess: all run
# side by side with the project's tests that do not read the built book, on four workers
# (README "Tests"). --maxschedchunk=1: xdist hands each worker its next test as it finishes one
# (by default it deals out a quarter of a worker's share at once, so all the tests marked long,
# collected first, went to one worker). Every limit of the tests is CPU time, or a wall-clock
# backstop far above it.
# numba compiles a kernel when a process first calls it, and caches it on disk (solutions/_fast/
# __pycache__). On a fresh clone every process of make test that calls the reference (the
# gradings, the kernel tests, the book) would compile them all at once: a minute of CPU each.
# A grading of the reference compiles them once, before the rest starts; beside it, a second one,
# bounds-checked, fills the cache of test_kernels' bounds-checked run (it ignores the flag, hence
# its own folder). About 70 s on a fresh clone, 10 s when the caches are warm.
NUMBA_CHECKED_CACHE := _build/numba-boundscheck
numba-cache: setup $(NUMBA_STAMP)
	{ $(BIN)/python -m grading grade --reference --results _build/numba-cache.json > _build/numba-cache.log 2>&1; \
	  echo $$? > _build/numba-cache.status; } & \
	NUMBA_BOUNDSCHECK=1 NUMBA_CACHE_DIR=$(NUMBA_CHECKED_CACHE) $(BIN)/python -m grading grade --reference \
	    --results _build/numba-cache-checked.json > _build/numba-cache-checked.log 2>&1; checked=$$?; wait; \
	if [ "$$(cat _build/numba-cache.status)" != 0 ] || [ $$checked != 0 ]; then \
	    tail -n 20 _build/numba-cache.log _build/numba-cache-checked.log; \
	    echo "make numba-cache: grading the reference failed"; exit 1; fi

# The tests' processes (four workers beside the book on two cores) run their linear algebra on one
# BLAS and OpenMP thread, as the grader's do (grading.config.GRADER_ENVIRONMENT, read from there):
# threads spinning on a machine already full cost more than they give (a subset of the project's
# tests took 65 s of wall clock and 52 s of CPU with OpenBLAS's default threads, 38 s and 40 s with one).
# The book's build keeps the defaults: its timings are the ones it publishes.
TEST_THREADS = $(shell $(BIN)/python -c "from grading.config import GRADER_ENVIRONMENT as e; \
    print(' '.join(f'{k}={v}' for k, v in e.items()))")
test: lint $(CODE_STAMP) $(NUMBA_STAMP) numba-cache
	@if [ -d _build/.jupyter_cache ]; then $(MAKE) --no-print-directory notebooks || exit 1; \
	    echo "Building the book and checking it (_build/book.log), nbval (_build/nbval.log), beside the tests"; \
	else rm -rf _build/notebooks; \
	    echo "Building the book, every page executed, and checking it (_build/book.log), beside the tests"; fi
	{ $(BIN)/jupyter-book build . -W -n --keep-going > _build/book.log 2>&1; status=$$?; \
	  if [ $$status = 0 ]; then $(BIN)/python -m pytest -p no:xdist -p no:cacheprovider -q -m book \
	      >> _build/book.log 2>&1; status=$$?; fi; echo $$status > _build/book.status; } & \
	{ if [ -d _build/notebooks ]; then $(BIN)/python -m pytest -p no:xdist --nbval-lax _build/notebooks \
	      > _build/nbval.log 2>&1; echo $$? > _build/nbval.status; \
	  else echo "nbval: not run, the book's build executed every page (no execution cache)" > _build/nbval.log; \
	      echo 0 > _build/nbval.status; fi; } & \
	env $(TEST_THREADS) $(BIN)/python -m pytest -n 4 --maxschedchunk=1 --durations=20 -m "not book"; tests=$$?; \
	wait; tail -n 1 _build/nbval.log; tail -n 1 _build/book.log; \
	if [ "$$(cat _build/book.status)" != 0 ]; then cat _build/book.log; echo "make test: the book's build or its checks failed"; exit 1; fi; \
	if [ "$$(cat _build/nbval.status)" != 0 ]; then cat _build/nbval.log; echo "make test: nbval failed"; exit 1; fi; \
	if [ $$tests != 0 ]; then echo "make test: tests failed"; exit 1; fi

# tests/images: debootstrap roots of the distributions, run with bwrap (README
# "Environments"). About 10 minutes; the roots are kept in build/images.
test-images: setup
	$(BIN)/python -m pytest tests/images -p no:xdist -p no:cacheprovider -o timeout=3600 -v -s

grade: setup $(NUMBA_STAMP)
	@test -n "$(SUBMISSION)" || { echo "usage: make grade SUBMISSION=path/to/student/clone"; exit 2; }
	$(BIN)/python -m grading grade "$(SUBMISSION)" --results "$(RESULTS)"

# The archive instructors upload to Gradescope as an assignment's autograder,
# one per lecture (ASSIGNMENT=lecture1, lecture2 or lecture3, grading.config.ASSIGNMENTS):
# grader, stubs, public and hidden tests, setup.sh and run_autograder; no
# solutions (it is scanned for them). README "Running a class".
gradescope: setup
	$(BIN)/python -m grading gradescope "$(GRADESCOPE_ZIP)" --assignment $(ASSIGNMENT)

# Benchmarks (benchmarks/README.md): pytest-benchmark, serial (no xdist: the
# implementations use both cores), no per-test timeout. The summary, committed,
# feeds the book's appendix. BENCH_ARGS passes options, e.g.
#   make bench BENCH_ARGS="--bench-sizes=100000 -k normals"
# BENCH_MERGE=1 keeps the committed results of the cases a partial run did not measure.
BENCH_ARGS ?=
BENCH_OUT  ?= benchmarks/results
bench: setup $(NUMBA_STAMP)
	mkdir -p _build/bench
	$(BIN)/python -m pytest benchmarks -p no:xdist -p no:dash -p no:cacheprovider -o addopts= -o timeout=0 \
	    -q --benchmark-json=_build/bench/raw.json --benchmark-save-data --benchmark-columns=median,iqr,rounds \
	    --benchmark-sort=name $(BENCH_ARGS)
	$(BIN)/python -m benchmarks.report _build/bench/raw.json $(BENCH_OUT) $(if $(BENCH_MERGE),--merge)

# Re-pin the lock, requirements/course.txt, from requirements/course.in, then
# its two subsets, grading.txt and student.txt, with the lock as constraints.
# uv resolves for every platform at once (--universal) and for the oldest
# supported Python, whatever runs it; the existing pins are kept where they
# still resolve. uv itself is pinned in the lock. README "Environments".
PYTHON_FLOOR := 3.11.0
UV_COMPILE    = $(CURDIR)/$(BIN)/uv pip compile --quiet --universal --python-version $(PYTHON_FLOOR) \
                --custom-compile-command "make requirements"
requirements: setup
	cd requirements && $(UV_COMPILE) course.in -o course.txt
	cd requirements && for env in grading student; do $(UV_COMPILE) $$env.in -c course.txt -o $$env.txt || exit 1; done

clean:
	rm -rf _build results build
