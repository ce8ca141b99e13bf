"""Lazy package attributes (PEP 562): a package's public names are imported on first use, so
``import cablelife`` and ``cablelife --help`` do not pay for numpy, scipy, h5py, pydantic … of
modules they never touch. ``from cablelife.lda import compare`` works as before.

A package calls ``lazy_package(__name__, {"module": ["name", ...]})`` instead of importing its
submodules. Where an exported function has the name of its submodule (``lda.compare``,
``signals.generate``), importing the submodule does not replace the function on the package
(as with eager imports, the package attribute is the function)."""

from __future__ import annotations

import importlib
import sys
import types


class _LazyPackage(types.ModuleType):
    """A package module whose exported names are imported from their modules on first use."""

    def __getattr__(self, name: str):
        module = self.__dict__.get("_lazy_exports", {}).get(name)
        if module is None:
            raise AttributeError(f"module {self.__name__!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        types.ModuleType.__setattr__(self, name, value)
        return value

    def __setattr__(self, name: str, value) -> None:
        exports = self.__dict__.get("_lazy_exports", {})
        if (
            name in exports
            and isinstance(value, types.ModuleType)
            and value.__name__ == f"{self.__name__}.{name}"
        ):
            return  # the import system binding a submodule over the function of the same name
        types.ModuleType.__setattr__(self, name, value)

    def __dir__(self) -> list[str]:
        return sorted(set(super().__dir__()) | set(self.__dict__.get("_lazy_exports", {})))


def lazy_package(package: str, exports: dict[str, list[str]]) -> list[str]:
    """Makes ``package`` (its ``__name__``) import the names of ``exports`` (module → names)
    on first use; returns the names for ``__all__``."""
    module = sys.modules[package]
    names = {n: m for m, ns in exports.items() for n in ns}
    module.__dict__["_lazy_exports"] = names
    module.__class__ = _LazyPackage
    return sorted(names)
