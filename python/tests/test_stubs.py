"""The type stubs installed next to the module describe what it has."""
import ast
import inspect
import pathlib

import pytest

import hausdorff

STUB = pathlib.Path(hausdorff._hausdorff.__file__).with_name("_hausdorff.pyi")


def stub_tree():
    assert STUB.exists(), f"no stub file at {STUB}"
    return ast.parse(STUB.read_text())


def params(fn):
    """(name, kind) of every parameter of a stub's function definition."""
    a = fn.args
    out = [(p.arg, "POSITIONAL_OR_KEYWORD") for p in a.posonlyargs + a.args]
    return out + [(p.arg, "KEYWORD_ONLY") for p in a.kwonlyargs]


def runtime_params(obj):
    ps = list(inspect.signature(obj).parameters.values())
    out = [(p.name, "POSITIONAL_OR_KEYWORD" if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)
            else p.kind.name) for p in ps]
    return out


def test_every_public_name_is_in_the_stubs():
    tree = stub_tree()
    names = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    names |= {t.target.id for t in tree.body if isinstance(t, ast.AnnAssign)}
    assert set(hausdorff.__all__) <= names, set(hausdorff.__all__) - names


@pytest.mark.parametrize("name", ["directed", "hausdorff", "distances", "percentile",
                                  "summary", "mean", "chamfer", "read", "formats"])
def test_function_signatures_match(name):
    defs = [n for n in stub_tree().body if isinstance(n, ast.FunctionDef) and n.name == name]
    assert defs
    for d in defs:                                     # every overload
        assert params(d) == runtime_params(getattr(hausdorff, name))


def test_index_and_result_classes_match():
    classes = {n.name: n for n in stub_tree().body if isinstance(n, ast.ClassDef)}
    for cname in ("Index", "DirectedResult", "HausdorffResult", "PercentileResult",
                  "MeanResult", "Summary"):
        runtime = getattr(hausdorff, cname)
        for item in classes[cname].body:
            if not isinstance(item, ast.FunctionDef) or item.name.startswith("__"):
                continue
            assert hasattr(runtime, item.name), f"{cname}.{item.name}"
            is_property = any(getattr(d, "id", None) == "property" for d in item.decorator_list)
            if not is_property:
                got = runtime_params(getattr(runtime, item.name))
                assert params(item) == got, f"{cname}.{item.name}"
    init = [f for f in classes["Index"].body if getattr(f, "name", "") == "__init__"][0]
    assert params(init)[1:] == runtime_params(hausdorff.Index)
