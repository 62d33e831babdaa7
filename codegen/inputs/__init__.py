"""Data files into records: one reader per format, shared by every application.

- :mod:`.records`: what readers hand out (Record, Unreadable, Notice) and InputError;
- :mod:`.dispatch`: the kind of a file (from its extension) and its reader;
- :mod:`.documents`: JSON, JSON Lines, YAML; :mod:`.payloads`: hex and raw binary payloads;
- :mod:`.ulog`: PX4 flight logs; :mod:`.tlog`: MAVLink telemetry logs and raw MAVLink streams;
- :mod:`.parameter_files` (parse and write) and :mod:`.parameter_records`: .param / .params files;
- :mod:`.devicetree`: .dts/.dtsi source and .dtb blobs;
- :mod:`.model`: what readers and applications use of a generated package, as Protocols.

Readers take the IR and the generated classes; they never import a frontend or a backend.
"""
