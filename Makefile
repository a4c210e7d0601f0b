# Two commands on a fresh machine with Python >= 3.11 and gcc:
#   make derive   set up .venv (if missing), derive every model and emit generated/
#   make test     regenerate into a temporary folder and diff (stale generated/ fails),
#                 then run the test suite
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: setup derive test test-unit check-generated pytest bench clean

setup: $(STAMP)

$(STAMP): pyproject.toml constraints.txt
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c constraints.txt -e ".[derive,test]"
	@touch $(STAMP)

derive: $(STAMP)
	$(PY) -m derive --out generated

check-generated: $(STAMP)
	@tmp=$$(mktemp -d) && \
	$(PY) -m derive --out $$tmp/generated && \
	if diff -r -x __pycache__ generated $$tmp/generated >$$tmp/diff.txt; then \
		echo "check-generated: generated/ is up to date"; rm -rf $$tmp; \
	else \
		head -40 $$tmp/diff.txt; \
		echo "check-generated: generated/ is STALE: run 'make derive' and commit it"; rm -rf $$tmp; exit 1; \
	fi

pytest: $(STAMP)
	$(PY) -m pytest -q

test: check-generated pytest

test-unit: $(STAMP)
	$(PY) -m pytest -q -m unit

bench: $(STAMP)
	$(PY) -m bench

clean:
	rm -rf $(VENV) .pytest_cache build *.egg-info
