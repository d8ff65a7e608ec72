"""Files in and out, at the edge of the package: the atomic writer (atomic.py: whole
or nothing, streams, several outputs together) and the results' tables (tables.py:
CSV and Parquet, whole or a chunk at a time)."""
