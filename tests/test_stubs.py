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
        if name.endswith("Error"):
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


def test_package_layout_and_earlier_module_paths():
    import softrod.analysis
    import softrod.cli
    import softrod.io
    import softrod.plot
    import softrod.study
    import softrod.workspace

    assert softrod.study.seed001_study is softrod.analysis.study.seed001_study
    assert softrod.workspace.workspace_map is softrod.workspace_map
    assert callable(softrod.cli.main) and callable(softrod.plot.plot_rod)
    assert softrod.io.read_backbone_csv is softrod.read_backbone_csv
