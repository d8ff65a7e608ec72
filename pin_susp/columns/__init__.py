"""The columns: metric functions of solved points and the registry that declares each
column once (name, unit, derivatives). README, How it works; docs/results.md."""
