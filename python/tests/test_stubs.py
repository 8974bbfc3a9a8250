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


def _stub_parameters(node):
    """A stub's parameters as (name, has a default), `self` left out."""
    args = node.args
    positional = args.posonlyargs + args.args
    defaults = [False] * (len(positional) - len(args.defaults)) + [True] * len(args.defaults)
    pairs = list(zip([a.arg for a in positional], defaults))
    pairs += [(a.arg, d is not None) for a, d in zip(args.kwonlyargs, args.kw_defaults)]
    return [(n, d) for n, d in pairs if n != "self"]


def _runtime_parameters(obj):
    return [(p.name, p.default is not inspect.Parameter.empty)
            for p in inspect.signature(obj).parameters.values() if p.name != "self"]


def test_every_compiled_function_has_its_stubs_arguments_and_defaults():
    # The stub of each compiled function against the module itself (its text signature):
    # the same argument names in the same order, and a default exactly where the module
    # has one — a keyword added to the extension and not to its stub fails here.
    stubs = stub_names(STUBS / "_asperity.pyi")
    checked, wrong = 0, []
    for name in dir(_asperity):
        obj = getattr(_asperity, name)
        if name.startswith("_") or not callable(obj) or isinstance(obj, type):
            continue
        assert isinstance(stubs[name], ast.FunctionDef), name
        if _stub_parameters(stubs[name]) != _runtime_parameters(obj):
            wrong.append(name)
        checked += 1
    assert wrong == []
    assert checked >= 20


def test_every_public_function_and_method_has_its_stubs_defaults():
    # The package's stubs (__init__.pyi) against the package: functions with their
    # defaults, and the methods of each public class (compiled or Python).
    stubs = stub_names(STUBS / "__init__.pyi")
    checked, wrong = 0, []
    for name in asperity.__all__:
        obj, stub = getattr(asperity, name, None), stubs.get(name)
        if inspect.isfunction(obj):
            if _stub_parameters(stub) != _runtime_parameters(obj):
                wrong.append(name)
            checked += 1
        elif inspect.isclass(obj) and isinstance(stub, ast.ClassDef):
            for node in stub.body:
                if not isinstance(node, ast.FunctionDef) or node.name.startswith("_"):
                    continue
                method = getattr(obj, node.name, None)
                assert method is not None, f"{name}.{node.name}: in the stub, not the class"
                if isinstance(method, property) or not callable(method):
                    continue
                try:
                    runtime = _runtime_parameters(method)
                except (TypeError, ValueError):  # a compiled method without a signature
                    continue
                if _stub_parameters(node) != runtime:
                    wrong.append(f"{name}.{node.name}")
                checked += 1
    assert wrong == []
    assert checked >= 40
