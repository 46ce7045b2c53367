# One-word commands. `make reproduce`, `make walk` and `make test` set everything up on a fresh machine first.
VENV ?= .venv
PY := $(VENV)/bin/python
OUT ?= out

.PHONY: setup reproduce walk test test-slow lint format window-map bench package-check clean docs-figures docs-tables

setup: $(VENV)/.installed

$(VENV)/.installed: pyproject.toml
	@command -v dot >/dev/null 2>&1 || { \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    apt-get update -qq && apt-get install -y -qq graphviz >/dev/null; \
	  else echo "note: Graphviz 'dot' is missing; diagram.svg/png will not be drawn (apt-get install graphviz)"; fi; }
	python3 -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[test]'
	# compile the controller's kernels once (numba caches them beside the sources)
	$(PY) -c "from drake_biped.episode import warm_up; warm_up()"
	touch $@

reproduce: setup
	$(VENV)/bin/drake-biped reproduce --quick --out $(OUT)/reproduce-quick

walk: setup
	$(VENV)/bin/drake-biped walk --out $(OUT)/walk

# The fast suite on both cores (pytest-xdist); the end-to-end simulations (marked slow) with `make test-slow`.
test: setup
	$(PY) -m pytest -q -n 2 -m "not slow"

test-slow: setup
	$(PY) -m pytest -q -n 2 -m slow

# Build the wheel, install it into a fresh venv and run the CLI, the API and an example outside the checkout.
package-check:
	bash .ci/package-check

lint: setup
	$(VENV)/bin/ruff check .

format: setup
	$(VENV)/bin/ruff format .

window-map: setup
	$(VENV)/bin/drake-biped window-map --out $(OUT)/window-map

# The pictures under docs/, drawn again from the committed records (tests/test_docs_figures.py checks them).
docs-figures: setup
	$(PY) benchmarks/docs_figures.py --out docs

# docs/PARAMETERS.md, the controller's parameters slot by slot, from their declarations (tests/test_parameters.py).
docs-tables: setup
	$(PY) -c "from drake_biped.control_law import parameter_markdown; print(parameter_markdown(), end='')" > docs/PARAMETERS.md

# Speed and time-step benchmarks (about 8 minutes on 2 cores): Markdown + JSON in out/bench, out/time-step-study.
bench: setup
	$(PY) benchmarks/bench.py --out $(OUT)/bench
	$(VENV)/bin/drake-biped time-step-study --out $(OUT)/time-step-study

clean:
	rm -rf $(OUT) .pytest_cache
