# roughfe: two commands do all set-up on a fresh Debian 12 machine.
#   make demo   installs what is missing, runs the default case, writes demo-output/
#   make test   installs what is missing, runs the test suite
#   make test-other-blas   the suite again on the other BLAS (OpenBLAS / reference)
#   make validate-quick   the reduced validation cases (CI, a few minutes); make validate: all
#   make docs   builds the documentation (docs/_build/html)
#   make bench-quick   the benchmarks at reduced sizes (4-5 min); make bench: all, full size
VENV   := .venv
PY     := $(VENV)/bin/python
# vtk renders off-screen through EGL; this silences its X11 warning.
export VTK_DEFAULT_OPENGL_WINDOW := vtkEGLRenderWindow
export PYVISTA_OFF_SCREEN := true
export MPLBACKEND := Agg
export OMPI_MCA_rmaps_base_oversubscribe := 1

JOBS   ?= 2

.PHONY: env test test-fast test-other-blas demo validate validate-quick bench bench-quick docs clean

env:
	@bash tools/bootstrap.sh

# make test is the CI command and runs EVERY test, slow ones included: the suite is the
# physics coverage (analytic solutions, FEM vs BEM, studies end to end) and takes 5.5-9 min
# on 2 cores with -n 2 (2011-2030 tests, sessions 39-41; measured:
# docs/validation/fem-convergence.md, "Speed of make test"). The 25 slowest are printed so that a new outlier is seen. make test-fast leaves
# out the tests marked @pytest.mark.slow (end-to-end CLI runs and studies, each several
# seconds) for the edit-test loop; it is not a substitute for make test.
# Both write bytecode even where the environment says PYTHONDONTWRITEBYTECODE (this
# machine's does): ~290 tests start the CLI in fresh interpreters, and each one compiled
# roughfe again (0.45 s -> 0.27 s an import; their 11 files 57.7 s -> 50.4 s, session 41).
TEST_ENV := env -u PYTHONDONTWRITEBYTECODE
test: env
	$(TEST_ENV) $(PY) -m pytest -q -p no:cacheprovider -n $(JOBS) --durations=25

test-fast: env
	$(TEST_ENV) $(PY) -m pytest -q -p no:cacheprovider -n $(JOBS) -m "not slow"

# make test-other-blas: the suite on the other BLAS/LAPACK than the one numpy loads here
# (OpenBLAS on this Debian's reference BLAS, or the reference on OpenBLAS), fetched by
# `apt-get download` into .venv/other-blas (tools/other_blas.sh; exit 3 when it cannot be
# had). A user's numbers must not hang on the BLAS's rounding (session 41: 11 failures).
# TEST_ARGS narrows it, e.g. TEST_ARGS='-m "not slow"' (what .ci/run runs).
TEST_ARGS ?=
test-other-blas: env
	bash tools/other_blas.sh $(TEST_ENV) $(PY) -m pytest -q -p no:cacheprovider -n $(JOBS) $(TEST_ARGS)

demo: env
	$(PY) -m roughfe.cli demo -o demo-output

# Every validation study (tens of minutes to hours on 2 shared cores: the FEM refinement
# study to r = 8 dominates); exits 1 while any target is NOT met (validation/output/summary.json).
# It installs the "bench" extra (the peer, Tamaas) so that the BEM-vs-Tamaas row runs.
# validate, bench, bench-quick and docs call the bootstrap once with their own extras
# instead of depending on env: a fresh venv then runs pip once, not twice.
validate:
	@bash tools/bootstrap.sh io,design,study,test,bench
	$(PY) -m roughfe.cli validate all -o validation/output

# The reduced cases of every study with their own targets (Westergaard/Hertz, one FEM case,
# sequencing on 3 seeds, a small leakage case, one design stage): < 3 min on a quiet machine.
validate-quick: env
	$(PY) -m roughfe.cli validate all --quick -o validation/output-quick

# make bench: every benchmark at full size (8192^2 BEM, 4096^2 Reynolds, Tamaas up to
# 512^2; over an hour on 2 cores, ~6.3 GB peak in the 4096^2 Reynolds solve), JSON in
# benchmarks/output and the one table of every speed/memory target in
# benchmarks/output/SUMMARY.md. make bench-quick:
# reduced sizes (4-5 min on 2 cores: 268 s in session 42, after bench_surface_design's
# quick run left out the x3p-2 design, 591 s of 802) into benchmarks/output-quick, for smoke use.
bench:
	@bash tools/bootstrap.sh io,design,study,test,bench
	$(PY) benchmarks/run_all.py

bench-quick:
	@bash tools/bootstrap.sh io,design,study,test,bench
	$(PY) benchmarks/run_all.py --quick

# HTML documentation in docs/_build/html (warnings are errors); the API, validation and
# benchmark pages are generated first from the sources and the JSON of validate/bench.
docs:
	@bash tools/bootstrap.sh io,design,study,test,docs
	$(PY) docs/generate.py
	$(PY) -m sphinx -W --keep-going -q -b html docs docs/_build/html
	@echo "open docs/_build/html/index.html"

clean:
	rm -rf demo-output validation/output validation/output-quick benchmarks/output benchmarks/output-quick .pytest_cache docs/_build docs/api/generated docs/validation/generated docs/benchmarks/generated docs/benchmarks/summary.md
