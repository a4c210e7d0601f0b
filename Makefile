# Two commands on a fresh machine with Python >= 3.11 and gcc:
#   make derive   set up .venv (if missing), derive every model and emit generated/
#   make test     regenerate into a temporary folder and diff (stale generated/ fails),
#                 then run the test suite
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
# cores for make derive (models and their emission side by side) and for pytest
JOBS   ?= 2

.PHONY: setup derive test test-unit check-generated pytest bench clean

setup: $(STAMP)

$(STAMP): pyproject.toml constraints.txt
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c constraints.txt -e ".[derive,test]"
	@touch $(STAMP)

derive: $(STAMP)
	$(PY) -m derive --out generated --jobs $(JOBS)

# A fresh derivation under another hash seed than the committing one's gives the committed
# bytes; `make test` tells the test suite so (tests/generated/test_generated.py does not derive again).
HASHSEED := 4242

check-generated: $(STAMP)
	@tmp=$$(mktemp -d) && \
	PYTHONHASHSEED=$(HASHSEED) $(PY) -m derive --out $$tmp/generated --jobs $(JOBS) && \
	if diff -r -x __pycache__ generated $$tmp/generated >$$tmp/diff.txt; then \
		echo "check-generated: generated/ is up to date"; rm -rf $$tmp; \
	else \
		head -40 $$tmp/diff.txt; \
		echo "check-generated: generated/ is STALE: run 'make derive' and commit it"; rm -rf $$tmp; exit 1; \
	fi

pytest: $(STAMP)
	$(PY) -m pytest -q -n $(JOBS)

test: export GYRO_GENERATED_CHECKED = $(HASHSEED)
test: check-generated pytest

test-unit: $(STAMP)
	$(PY) -m pytest -q -m unit

bench: $(STAMP)
	$(PY) -m bench

clean:
	rm -rf $(VENV) .pytest_cache build *.egg-info
