"""What a suspension is before anything is solved: the geometry file read and
checked, the mechanisms' kinematic trees, the tree and its URDF/MJCF text, labelled
corners composed, sweeps, dead centres at design. README, How it works."""
