"""PX4 ULog flight logs: per-record reading, the record index walked in C, whole columns and older layouts."""
