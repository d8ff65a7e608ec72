"""Pictures of a model: the meshcat scene and its server (``scene``, ``server``, the
parts drawn and the force colours), and the front and side drawings (``drawing``).
README, How it works."""
