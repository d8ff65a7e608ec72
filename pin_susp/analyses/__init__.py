"""Analyses on an Assembly: setup sheets and the inverse setup, member and joint
loads, hardpoint sensitivities, the independent point-based solve. README, How it
works."""
