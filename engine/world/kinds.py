"""The registry of shape kinds: one ``ShapeKind`` entry per kind, declared once on its shape class
(engine/world/shapes.py), read by the body store, the broad phase, the dispatch tables, the warm-up and the tests.

A kind's entry says what the world needs to know of it:

- ``code``: its row and column in the dispatch tables (the order of registration);
- ``bounded``: it has a finite AABB and enters the broad phase; an unbounded kind (a ground) is found by its
  own ``candidates(shape, lo, hi)`` test over the bodies' AABBs instead;
- ``static_only``: it never moves (level geometry: the grounds);
- ``convex``: a convex core swept by a ball, so GJK/EPA can answer any pair of two such kinds (the fallback
  rows of engine/world/rows.py) and it may be a part of a ``Compound``;
- ``composite``: made of parts that are bodies of other kinds, answered part by part (``Compound``).

A shape class registers its kind by its decorator (``@shape_kind("sphere")``) and carries the rest: the core
(``local`` points, ``radius``, ``half``), ``example()`` (a small instance: the warm-up compiles every row with it)
and ``random(rng, center, size)`` (the tests' strategies). A new kind is its decorated class in
engine/world/shapes.py, its rows in engine/world/rows.py, and new kernels in engine/narrowphase/ when it brings
new closed forms (engine/ARCHITECTURE.md, "Adding things").
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

__all__ = ["ShapeKind", "shape_kind", "KINDS", "kind_named"]


@dataclass(frozen=True, eq=False)
class ShapeKind:
    """One kind of shape, as the world sees it (see the module docstring).

    Attributes
    ----------
    name : str
        "sphere", "box", ... (the dispatch tables and ``World.kind`` name it so).
    shape : type
        Its shape class (a subclass of engine.world.shapes.Shape).
    code : int
        Its row and column in the dispatch tables, in order of registration.
    bounded, static_only, convex, composite : bool
        The flags of the module docstring.
    candidates : callable or None
        For an unbounded kind: ``candidates(shape, lo, hi) -> bool (n,)``, the bodies' AABBs ((n, 3) each) that
        may touch the shape.
    """

    name: str
    shape: Any  # the Shape subclass (engine.world.shapes imports this module, not the reverse)
    code: int
    bounded: bool = True
    static_only: bool = False
    convex: bool = True
    composite: bool = False
    candidates: Callable | None = field(default=None, repr=False)

    def __repr__(self) -> str:
        return f"ShapeKind({self.name!r})"


#: every registered kind, by code
KINDS: list[ShapeKind] = []


def shape_kind(name: str, **flags):
    """Class decorator: register the decorated shape class as a new kind under the next code, and set its
    ``kind`` attribute to the entry; ``flags`` are ``ShapeKind``'s (ValueError for a name taken, or an unbounded
    kind without ``candidates``)."""
    def register(cls):
        if any(k.name == name for k in KINDS):
            raise ValueError(f"a shape kind named {name!r} is already registered")
        kind = ShapeKind(name=name, shape=cls, code=len(KINDS), **flags)
        if not kind.bounded and kind.candidates is None:
            raise ValueError(f"the unbounded kind {name!r} needs its candidates test")
        KINDS.append(kind)
        cls.kind = kind
        return cls
    return register


def kind_named(name: str) -> ShapeKind:
    """The registered kind called ``name`` (KeyError naming the known ones otherwise)."""
    for kind in KINDS:
        if kind.name == name:
            return kind
    raise KeyError(f"no shape kind {name!r}; known: {[k.name for k in KINDS]}")
