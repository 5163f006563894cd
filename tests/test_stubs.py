"""The shipped ``_core.pyi`` stubs match the compiled module, name for name."""

import ast
import inspect
from pathlib import Path

import softrod
from softrod import _core

STUB = Path(softrod.__file__).with_name("_core.pyi")


def _stub_tree():
    return ast.parse(STUB.read_text())


def _public(names):
    return {n for n in names if not n.startswith("_") or n == "__version__"}


def test_every_module_name_is_stubbed_and_vice_versa():
    tree = _stub_tree()
    stubbed = set()
    for node in tree.body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            stubbed.add(node.name)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            stubbed.add(node.target.id)
    module = _public(n for n in dir(_core) if not inspect.ismodule(getattr(_core, n)))
    assert module - stubbed == set(), "names in _core but not in the stub"
    assert _public(stubbed) - module == set(), "names in the stub but not in _core"


def test_class_members_match():
    classes = {n.name: n for n in _stub_tree().body if isinstance(n, ast.ClassDef)}

    def members(node):
        own = {
            n.name
            for n in node.body
            if isinstance(n, ast.FunctionDef) and not n.name.startswith("_")
        }
        for base in node.bases:
            if isinstance(base, ast.Name) and base.id in classes:
                own |= members(classes[base.id])
        return own

    for name, node in classes.items():
        if name.endswith(("Error", "Warning")):
            continue
        real = {n for n in dir(getattr(_core, name)) if not n.startswith("_")}
        assert members(node) == real, name


def test_solve_signature_matches_stub():
    sig = inspect.signature(_core.PlanarCableArm.solve)
    assert list(sig.parameters) == [
        "self",
        "tension",
        "n_points",
        "s",
        "method",
        "rtol",
        "atol",
        "max_steps",
    ]
    for node in _stub_tree().body:
        if isinstance(node, ast.ClassDef) and node.name == "PlanarCableArm":
            fn = next(n for n in node.body if isinstance(n, ast.FunctionDef) and n.name == "solve")
            names = [a.arg for a in fn.args.args + fn.args.kwonlyargs]
            assert names == list(sig.parameters)
            defaults = [ast.literal_eval(d) for d in fn.args.defaults + fn.args.kw_defaults]
            real = [p.default for p in sig.parameters.values() if p.default is not p.empty]
            assert defaults == real


def _stub_params(fn: ast.FunctionDef):
    """(name, kind, default) of a stub function's parameters; default `...` means "given"."""
    a = fn.args
    pos = a.posonlyargs + a.args
    defaults = [None] * (len(pos) - len(a.defaults)) + list(a.defaults)
    out = []
    for arg, d in zip(pos, defaults, strict=True):
        out.append((arg.arg, "positional", d))
    if a.vararg:
        out.append((a.vararg.arg, "var_positional", None))
    for arg, d in zip(a.kwonlyargs, a.kw_defaults, strict=True):
        out.append((arg.arg, "keyword_only", d))
    if a.kwarg:
        out.append((a.kwarg.arg, "var_keyword", None))
    return out


def _default(node):
    if node is None:
        return inspect.Parameter.empty
    if isinstance(node, ast.Constant) and node.value is Ellipsis:
        return Ellipsis
    return ast.literal_eval(node)


def _compare(stub: ast.FunctionDef, real, what: str, drop_first: bool):
    sig = inspect.signature(real)
    got = []
    for p in sig.parameters.values():
        kind = {
            p.POSITIONAL_ONLY: "positional",
            p.POSITIONAL_OR_KEYWORD: "positional",
            p.KEYWORD_ONLY: "keyword_only",
            p.VAR_POSITIONAL: "var_positional",
            p.VAR_KEYWORD: "var_keyword",
        }[p.kind]
        got.append((p.name, kind, p.default))
    want = _stub_params(stub)
    if drop_first and want and want[0][0] in ("self", "cls"):
        want = want[1:]
    if got and got[0][0] in ("self", "cls", "$self", "$cls"):
        got = got[1:]
    assert [(n, k) for n, k, _ in got] == [(n, k) for n, k, _ in want], what
    for (name, _, real_default), (_, _, node) in zip(got, want, strict=True):
        d = _default(node)
        if d is Ellipsis:
            assert real_default is not inspect.Parameter.empty, f"{what}: {name} has a default"
        elif d is inspect.Parameter.empty:
            assert real_default is inspect.Parameter.empty, f"{what}: {name} has no default"
        else:
            assert real_default == d, f"{what}: default of {name}: {real_default!r} vs {d!r}"


def test_every_public_signature_matches_the_stub():
    checked = 0
    for node in _stub_tree().body:
        if isinstance(node, ast.FunctionDef) and not node.name.startswith("_"):
            _compare(node, getattr(_core, node.name), node.name, drop_first=False)
            checked += 1
        elif isinstance(node, ast.ClassDef) and not node.name.endswith("Error"):
            cls = getattr(_core, node.name)
            for fn in node.body:
                if not isinstance(fn, ast.FunctionDef):
                    continue
                decorators = {getattr(d, "id", getattr(d, "attr", None)) for d in fn.decorator_list}
                if "property" in decorators or (
                    fn.name.startswith("__")
                    and fn.name
                    not in (
                        "__init__",
                        "__new__",
                    )
                ):
                    continue
                real = cls if fn.name in ("__init__", "__new__") else getattr(cls, fn.name)
                _compare(fn, real, f"{node.name}.{fn.name}", drop_first=True)
                checked += 1
    assert checked > 60, checked


def test_package_layout_and_earlier_module_paths():
    import softrod.analysis
    import softrod.cli
    import softrod.io
    import softrod.plot
    import softrod.study
    import softrod.workspace

    assert softrod.study.compliance_study is softrod.analysis.study.compliance_study
    assert softrod.workspace.workspace_map is softrod.workspace_map
    assert callable(softrod.cli.main) and callable(softrod.plot.plot_rod)
    assert softrod.io.read_backbone_csv is softrod.read_backbone_csv
