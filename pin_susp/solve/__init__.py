"""Solving: a tree as a Pinocchio model with its closures (``linkage``), Newton for one
configuration (``solver``), many at once (``bulk``), a sweep's steps (``march``), a
spring's rates, and the setup a corner is built on (``shim``, ``as_set``). README,
How it works."""
