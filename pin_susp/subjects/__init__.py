"""What is solved: the one Assembly of labelled corners and their shared elements
(``assembly``, ``elements/``), built from a corner's or an axle's file (``corner``,
``axle``, ``axle_file``); ``subject`` reads a file's kind. README, How it works."""
