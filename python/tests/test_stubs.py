"""The type stubs describe what the package exports: every public name and every compiled
function has a stub, with the same keyword arguments for the public functions."""

import ast
import inspect
from pathlib import Path

import asperity
from asperity import _asperity

STUBS = Path(asperity.__file__).parent


def stub_names(path):
    tree = ast.parse(path.read_text())
    names = {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names[node.name] = node
        elif isinstance(node, ast.ImportFrom):
            names.update({a.asname or a.name: node for a in node.names})
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names[node.target.id] = node  # a constant: `NAME: float`
    return names


def test_public_names_have_stubs_with_the_same_arguments():
    stubs = stub_names(STUBS / "__init__.pyi")
    for name in asperity.__all__:
        if name == "__version__":
            continue
        assert name in stubs, name
        obj = getattr(asperity, name)
        if inspect.isfunction(obj):
            stub_args = [a.arg for a in stubs[name].args.args + stubs[name].args.kwonlyargs]
            assert stub_args == list(inspect.signature(obj).parameters), name


def test_compiled_functions_have_stubs():
    stubs = stub_names(STUBS / "_asperity.pyi")
    public = [n for n in dir(_asperity) if not n.startswith("_")]
    assert public and all(n in stubs for n in public), set(public) - set(stubs)


def test_the_package_is_typed():
    assert (STUBS / "py.typed").exists()
