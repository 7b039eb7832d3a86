"""The shipped type stubs (roboticplatform/_roboticplatform.pyi) against the compiled module: every
public name of the module and of each class is in the stubs and every name of the stubs is in the
module, of the same kind (class, function, method, property), with the same parameters (names, and
which have defaults, and equal literal defaults) as pybind11's signatures. So the stubs cannot
drift from python/src/*.cpp unnoticed."""
import ast
import inspect
import re
import types
from pathlib import Path

import pytest

import roboticplatform
from roboticplatform import _roboticplatform as module

STUBS = Path(module.__file__).with_name("_roboticplatform.pyi")


def public(name):
    return not name.startswith("_")


def stub_tree():
    return ast.parse(STUBS.read_text(), filename=str(STUBS))


def stub_top_level(tree):
    """Top-level names the stubs give the module: classes, functions and assignments."""
    names = {}
    for node in tree.body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            names[node.name] = node
        elif isinstance(node, ast.Assign):
            for target in node.targets:
                names[target.id] = node
        elif isinstance(node, ast.AnnAssign):
            names[node.target.id] = node
    return names


def stub_members(classes, name):
    """The members the stubs give class `name`, its stub bases' included: {name: FunctionDef}."""
    node = classes[name]
    members = {}
    for base in node.bases:
        if isinstance(base, ast.Name) and base.id in classes:
            members.update(stub_members(classes, base.id))
    for item in node.body:
        if isinstance(item, ast.FunctionDef):
            members[item.name] = item
        elif isinstance(item, ast.AnnAssign):
            members[item.target.id] = item
    return members


def runtime_members(cls):
    """The members the module defines for `cls` (its bases from the module included, not object's,
    pybind11's or the built-in exceptions')."""
    members = {}
    for klass in reversed(cls.__mro__):
        if klass.__module__ == module.__name__:
            members.update(vars(klass))
    return members


def is_property(node):
    return isinstance(node, ast.FunctionDef) and any(
        isinstance(d, ast.Name) and d.id == "property" for d in node.decorator_list)


def split_top_level(text):
    """Splits `a: x[b, c] = 1, d` at the commas outside brackets and quotes."""
    parts, depth, quote, current = [], 0, None, ""
    for c in text:
        if quote:
            quote = None if c == quote else quote
        elif c in "'\"":
            quote = c
        elif c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        elif c == "," and depth == 0:
            parts.append(current.strip())
            current = ""
            continue
        current += c
    if current.strip():
        parts.append(current.strip())
    return parts


def runtime_parameters(function, name):
    """[(parameter, default text or None)] from pybind11's signature line `name(a: T = d, ...) -> R`."""
    doc = function.__doc__ or ""
    first = doc.lstrip().splitlines()[0] if doc.strip() else ""
    assert first.startswith(name + "("), f"{name}: no pybind11 signature in its docstring: {first!r}"
    assert not doc.lstrip().startswith(name + "(*args, **kwargs)\nOverloaded"), f"{name}: overloads: compare by hand"
    inner, depth = "", 0
    for c in first[len(name):]:
        depth += c == "("
        depth -= c == ")"
        if depth == 0:
            break
        inner += c
    parameters = []
    for part in split_top_level(inner[1:]):
        head, _, default = part.partition(" = ")
        parameters.append((head.split(":")[0].strip(), default or None))
    return parameters


def stub_parameters(node):
    """[(parameter, default node or None)], with ("*", None) before keyword-only parameters as
    pybind11's signatures write them (py::kw_only)."""
    args = node.args
    assert not args.vararg and not args.kwarg and not args.posonlyargs, node.name
    defaults = [None] * (len(args.args) - len(args.defaults)) + list(args.defaults)
    parameters = [(a.arg, d) for a, d in zip(args.args, defaults)]
    if args.kwonlyargs:
        parameters.append(("*", None))
        parameters += list(zip((a.arg for a in args.kwonlyargs), args.kw_defaults))
    return parameters


def literal(text_or_node):
    try:
        if isinstance(text_or_node, ast.AST):
            return ast.literal_eval(text_or_node)
        return ast.literal_eval(text_or_node)
    except (ValueError, SyntaxError):
        return Ellipsis


def check_signature(where, function, name, node):
    expected = runtime_parameters(function, name)
    stubbed = stub_parameters(node)
    assert [p for p, _ in stubbed] == [p for p, _ in expected], f"{where}: parameters differ"
    for (parameter, default), (_, stub_default) in zip(expected, stubbed):
        assert (default is None) == (stub_default is None), f"{where}({parameter}): a default in one only"
        if default is not None:
            got, want = literal(stub_default), literal(default)
            if got is not Ellipsis and want is not Ellipsis:
                assert got == want, f"{where}({parameter}): default {got!r} in the stubs, {want!r} in the module"


def test_the_stubs_ship_next_to_the_module_and_parse():
    assert STUBS.is_file()
    assert (STUBS.parent / "py.typed").is_file()
    stub_tree()


def test_every_public_name_of_the_module_is_in_the_stubs_and_vice_versa():
    stubs = {n for n in stub_top_level(stub_tree()) if public(n)}
    runtime = {n for n in dir(module) if public(n) and not inspect.ismodule(getattr(module, n))}
    assert sorted(runtime - stubs) == [], "in the module, missing from the stubs"
    assert sorted(stubs - runtime) == [], "in the stubs, not in the module"
    # The package re-exports every one of them.
    assert sorted(n for n in runtime if not hasattr(roboticplatform, n)) == []


def test_every_module_function_has_the_stubs_signature():
    top = stub_top_level(stub_tree())
    for name, node in top.items():
        if not public(name):
            continue
        value = getattr(module, name)
        if isinstance(node, ast.FunctionDef):
            assert callable(value) and not inspect.isclass(value), f"{name}: a function in the stubs only"
            check_signature(name, value, name, node)
        elif isinstance(node, ast.ClassDef):
            assert inspect.isclass(value), f"{name}: a class in the stubs only"


CLASSES = sorted(n for n in dir(module) if public(n) and inspect.isclass(getattr(module, n)))


@pytest.mark.parametrize("name", CLASSES)
def test_every_public_member_of_each_class_is_in_the_stubs_and_vice_versa(name):
    classes = {n: c for n, c in stub_top_level(stub_tree()).items() if isinstance(c, ast.ClassDef)}
    assert name in classes
    cls = getattr(module, name)
    # The bases the module gives the class are the stubs' (by name; built-in exceptions too).
    stub_bases = [b.id for b in classes[name].bases if isinstance(b, ast.Name)]
    runtime_bases = [b.__name__ for b in cls.__bases__ if b.__module__ in (module.__name__, "builtins")]
    assert stub_bases == runtime_bases, f"{name}: bases"
    stubbed = stub_members(classes, name)
    runtime = runtime_members(cls)
    runtime_public = {n for n in runtime if public(n)}
    stubbed_public = {n for n in stubbed if public(n)}
    assert sorted(runtime_public - stubbed_public) == [], f"{name}: in the module, missing from the stubs"
    assert sorted(stubbed_public - runtime_public) == [], f"{name}: in the stubs, not in the module"
    for member in sorted(runtime_public):
        value, node = runtime[member], stubbed[member]
        where = f"{name}.{member}"
        if isinstance(value, property):
            assert is_property(node), f"{where}: a property in the module, not in the stubs"
        else:
            assert not is_property(node), f"{where}: a property in the stubs, not in the module"
            check_signature(where, getattr(cls, member), member, node)
    # A constructor in the module is one in the stubs, with the same parameters, and vice versa. A
    # class without one has pybind11's slot wrapper that raises "No constructor defined".
    if "__init__" in runtime and not isinstance(runtime["__init__"], types.WrapperDescriptorType):
        assert "__init__" in stubbed, f"{name}: the module has a constructor, the stubs none"
        check_signature(f"{name}.__init__", cls.__init__, "__init__", stubbed["__init__"])
    elif issubclass(cls, BaseException):
        pass  # the built-in exception's constructor
    else:
        assert "__init__" not in stubbed, f"{name}: the stubs have a constructor, the module none"


def _text_after_signature(doc, name):
    """A docstring's text besides pybind11's signature lines."""
    lines = [line.strip() for line in (doc or "").strip().splitlines()]
    return " ".join(line for line in lines
                     if line and not line.startswith(name + "(") and line != "Overloaded function."
                     and not re.match(r"\d+\. " + re.escape(name) + r"\(", line)).strip()


def test_every_public_name_and_member_has_a_docstring():
    # help(), editors and notebooks show these: the C++ documentation's one-line summaries.
    undocumented = []
    for name in sorted(n for n in dir(module) if public(n) and not inspect.ismodule(getattr(module, n))):
        obj = getattr(module, name)
        if inspect.isclass(obj):
            if not (obj.__doc__ or "").strip():
                undocumented.append(name)
            for member, value in vars(obj).items():
                if member.startswith("_"):
                    continue
                doc = (value.__doc__ or "").strip() if isinstance(value, property) else \
                    _text_after_signature(getattr(obj, member).__doc__, member)
                if not doc:
                    undocumented.append(f"{name}.{member}")
        elif callable(obj) and not _text_after_signature(obj.__doc__, name):
            undocumented.append(name)
    assert not undocumented, f"{len(undocumented)} without a docstring: {undocumented}"
