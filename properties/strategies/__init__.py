"""Shared Hypothesis strategies, one submodule per area (dynamics, boxes, geometry, gas).

Import from the submodule: ``from properties.strategies.dynamics import heights``.
"""
