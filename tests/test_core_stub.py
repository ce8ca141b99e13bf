"""The type stub `python/cablelife/_core.pyi` names exactly what the extension exports: every
function, class, method and constant of `cablelife._core`, with its argument names."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import cablelife._core as core

STUB = Path(__file__).resolve().parents[1] / "python" / "cablelife" / "_core.pyi"


def _stub() -> dict[str, object]:
    tree = ast.parse(STUB.read_text())
    names: dict[str, object] = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            names[node.name] = [a.arg for a in node.args.args]
        elif isinstance(node, ast.ClassDef):
            names[node.name] = {
                f.name: [a.arg for a in f.args.args][1:]
                for f in node.body
                if isinstance(f, ast.FunctionDef) and not f.name.startswith("__")
            }
        elif isinstance(node, ast.AnnAssign):
            names[node.target.id] = None
    return names


def _arguments(obj) -> list[str]:
    sig = obj.__text_signature__ or "()"
    inner = sig.strip("()").replace("$self", "").split(",")
    return [a.split("=")[0].strip().lstrip("*") for a in inner if a.strip()]


def test_stub_lists_every_export_with_its_arguments():
    stub = _stub()
    public = {n for n in dir(core) if not n.startswith("_")}
    assert set(stub) == public, (public - set(stub), set(stub) - public)
    for name in public:
        obj = getattr(core, name)
        if inspect.isclass(obj):
            methods = {m for m in dir(obj) if not m.startswith("_")}
            assert set(stub[name]) == methods, (name, methods ^ set(stub[name]))
            for m in methods:
                member = getattr(obj, m)
                if callable(member) and getattr(member, "__text_signature__", None):
                    assert stub[name][m] == _arguments(member), (name, m)
        elif callable(obj):
            assert stub[name] == _arguments(obj), name
