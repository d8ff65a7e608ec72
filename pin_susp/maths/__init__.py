"""Maths under every layer: vectors (unit vectors, the coincident-point tolerance) and
dual numbers (``jet``: exact derivatives of any metric). README, How it works."""
