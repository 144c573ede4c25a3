# roughfe: two commands do all set-up on a fresh Debian 12 machine.
#   make demo   installs what is missing, runs the default case, writes demo-output/
#   make test   installs what is missing, runs the test suite
#   make docs   builds the documentation (docs/_build/html)
VENV   := .venv
PY     := $(VENV)/bin/python
# vtk renders off-screen through EGL; this silences its X11 warning.
export VTK_DEFAULT_OPENGL_WINDOW := vtkEGLRenderWindow
export PYVISTA_OFF_SCREEN := true
export MPLBACKEND := Agg
export OMPI_MCA_rmaps_base_oversubscribe := 1

.PHONY: env test demo validate bench docs clean

env:
	@bash tools/bootstrap.sh

test: env
	$(PY) -m pytest -q -p no:cacheprovider

demo: env
	$(PY) -m roughfe.cli demo -o demo-output

validate: env
	$(PY) -m roughfe.cli validate all -o validation/output

bench: env
	@bash tools/bootstrap.sh io,design,study,test,bench
	$(PY) benchmarks/run_all.py

# HTML documentation in docs/_build/html (warnings are errors); the API, validation and
# benchmark pages are generated first from the sources and the JSON of validate/bench.
docs: env
	@bash tools/bootstrap.sh io,design,study,test,docs
	$(PY) docs/generate.py
	$(PY) -m sphinx -W --keep-going -q -b html docs docs/_build/html
	@echo "open docs/_build/html/index.html"

clean:
	rm -rf demo-output validation/output benchmarks/output .pytest_cache docs/_build docs/api/generated docs/validation/generated docs/benchmarks/generated
