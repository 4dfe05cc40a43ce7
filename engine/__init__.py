"""engine — collision detection for game physics: whether, where and when two objects collide.

Every public name of DESIGN.md section 3 is importable from here.
"""
from __future__ import annotations

__version__ = "0.1.0"
