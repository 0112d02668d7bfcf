"""The package as installed: docstring examples run, the stubs match the
extension module, py.typed is shipped."""

import ast
import doctest
import inspect
import os
import pathlib

import pytest

import aniso_alpha
import aniso_alpha._api
import aniso_alpha._native

PACKAGE = pathlib.Path(aniso_alpha.__file__).parent


def _distributed():
    """aniso_alpha.distributed when dask.distributed is installed (always in CI)."""
    try:
        import dask.distributed  # noqa: F401
    except ImportError:
        if os.environ.get("CI"):
            raise
        return pytest.param(None, marks=pytest.mark.skip(reason="dask.distributed not installed"))
    import aniso_alpha.distributed

    return aniso_alpha.distributed


@pytest.mark.parametrize("module", [aniso_alpha, aniso_alpha._api, _distributed()])
def test_docstring_examples(module):
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.attempted > 0
    assert result.failed == 0


def test_every_public_function_has_an_example():
    for name in aniso_alpha.__all__:
        obj = getattr(aniso_alpha, name)
        if inspect.isfunction(obj):
            assert ">>> " in (obj.__doc__ or ""), f"{name} has no example"


def test_stubs_match_the_extension_module():
    stub = ast.parse((PACKAGE / "_native.pyi").read_text())
    declared = {
        f.name: [a.arg for a in f.args.args + f.args.kwonlyargs]
        for f in stub.body
        if isinstance(f, ast.FunctionDef)
    }
    classes = {
        c.name: {f.name for f in c.body if isinstance(f, ast.FunctionDef) and not f.name.startswith("__")}
        for c in stub.body
        if isinstance(c, ast.ClassDef)
    }
    native = {
        name: obj
        for name, obj in vars(aniso_alpha._native).items()
        if callable(obj) and not name.startswith("__") and not inspect.isclass(obj)
    }
    native_classes = {
        name: {m for m in vars(obj) if not m.startswith("__")}
        for name, obj in vars(aniso_alpha._native).items()
        if inspect.isclass(obj)
    }
    assert set(declared) == set(native)
    for name, fn in native.items():
        params = list(inspect.signature(fn).parameters)
        assert params == declared[name], name
    assert classes == native_classes


def test_py_typed_is_installed():
    assert (PACKAGE / "py.typed").is_file()
    assert (PACKAGE / "_native.pyi").is_file()


def test_version():
    assert aniso_alpha.__version__.count(".") == 2
