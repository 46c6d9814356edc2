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



PUBLIC_PACKAGES = ("footfall", "footfall.planner", "footfall.scenarios", "footfall.tuning")


def _public_api():
    """(package, name, object) of every function and class a package exports (its ``__all__``)."""
    import inspect

    out = []
    for package in PUBLIC_PACKAGES:
        module = importlib.import_module(package)
        for name in module.__all__:
            obj = getattr(module, name)
            if inspect.isfunction(obj) or inspect.isclass(obj):
                out.append((package, name, obj))
    return out


def test_every_public_function_and_class_has_numpydoc_sections_and_an_example():
    # scikit-image's rule: a public name carries its parameters (functions) and a doctested example,
    # which test_docstring_examples runs. A name added to an __all__ without them fails here.
    import inspect

    missing = []
    for package, name, obj in _public_api():
        doc = inspect.getdoc(obj) or ""
        wants = ["Examples\n--------"]
        if inspect.isfunction(obj) and inspect.signature(obj).parameters:
            wants.append("Parameters\n----------")
        lacking = [w.split("\n")[0] for w in wants if w not in doc]
        if ">>>" not in doc and "Examples" not in lacking:
            lacking.append("an example")
        if lacking:
            missing.append(f"{package}.{name}: {', '.join(lacking)}")
    assert len(_public_api()) >= 100
    assert not missing, f"{len(missing)} public names lack numpydoc sections:\n" + "\n".join(missing)
