"""A data file before its reader: its kind (content first, then its name) and the file held still while it is read."""
