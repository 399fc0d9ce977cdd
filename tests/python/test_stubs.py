"""The type stubs (recruit/_recruit.pyi) list exactly what the extension module defines, and
everything public has a docstring."""
import ast
import inspect
import pathlib

import recruit
from recruit import _recruit

STUB = pathlib.Path(recruit.__file__).with_name("_recruit.pyi")


def _stub_names():
    tree = ast.parse(STUB.read_text())
    funcs, classes = set(), {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            funcs.add(node.name)
        elif isinstance(node, ast.ClassDef):
            classes[node.name] = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
    return funcs, classes


def _public(obj):
    return {n for n in vars(obj) if not n.startswith("_") or n == "__init__"}


def test_stubs_match_the_module():
    funcs, classes = _stub_names()
    module_funcs = {n for n, v in vars(_recruit).items()
                    if not n.startswith("__") and callable(v) and not inspect.isclass(v)}
    module_classes = {n for n, v in vars(_recruit).items() if inspect.isclass(v)}
    assert funcs == module_funcs
    assert set(classes) == module_classes
    for name, members in classes.items():
        cls = getattr(_recruit, name)
        defined = _public(cls) - {"__init__"} if "__init__" not in members else _public(cls)
        if name == "_Filter":
            defined.discard("__init__")  # not constructible
        assert members == defined, name


def test_everything_public_has_a_docstring():
    for name in recruit.__all__:
        obj = getattr(recruit, name)
        if isinstance(obj, str):
            continue
        assert (obj.__doc__ or "").strip(), name
        if inspect.isclass(obj):
            for member, value in vars(obj).items():
                if member.startswith("_"):
                    continue
                assert (getattr(value, "__doc__", None) or "").strip(), f"{name}.{member}"
