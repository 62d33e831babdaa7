"""The engine of ``battgen export``: battery records of many logs into one Parquet dataset.

Needs the ``fleet`` extra (pyarrow, numpy; DuckDB for queries, dask.distributed for clusters).
Modules: :mod:`.catalog` (the concepts and mappings, from the IR), :mod:`.sources` (a log into
batches of columns), :mod:`.columnar` (the mappings over columns; the tests check it against the
generated converters record by record), :mod:`.columns`, :mod:`.table` (Arrow), :mod:`.dataset`
(the folder), :mod:`.engine` (runs), :mod:`.distributed` (Dask).
"""
