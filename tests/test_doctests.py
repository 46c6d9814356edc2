"""The examples in the docstrings run, and say what they show (issue 17: doctested examples, run by the
test command). Every module of the project's packages that has an example is one test."""

import doctest
import importlib
import pkgutil

import pytest

PACKAGES = ("footfall.planner", "footfall.scenarios", "footfall.tuning", "footfall.reports", "footfall",
            "footfall.cli", "footfall.benchmarks")


def _modules_with_examples():
    names = []
    for package in PACKAGES:
        root = importlib.import_module(package)
        for name in [package] + [f"{package}.{m.name}" for m in pkgutil.iter_modules(root.__path__)]:
            module = importlib.import_module(name)
            if any(t.examples for t in doctest.DocTestFinder(exclude_empty=True).find(module)):
                names.append(name)
    return names


MODULES = _modules_with_examples()


def test_the_examples_are_found():
    # A finder that found nothing would pass every module: at least the modules known to have examples.
    assert {"footfall.planner._workspace", "footfall.planner._crowd", "footfall.planner._threads",
            "footfall.reports._evaluate"} <= set(MODULES)


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    failures = []
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for test in doctest.DocTestFinder(exclude_empty=True).find(module):
        if test.examples:
            runner.run(test, out=failures.append)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, "".join(failures)

