"""Frontends: schema files -> IR (:mod:`codegen.ir`). They only produce IR; no format's package imports another.

One package per format, each with ``parse_dir`` and ``parse_file`` as its entry point: :mod:`.uorb`
(PX4 ``.msg``), :mod:`.dsdl` (DroneCAN ``.uavcan``), :mod:`.devicetree` (dt-schema YAML),
:mod:`.mavlink` (MAVLink XML dialects), :mod:`.pdef` (ArduPilot ``.pdef.xml`` parameter metadata).
:mod:`.mappings` (converters between formats) and :mod:`.rules` (cross-field rules) are read after
the formats, since they refer to their messages; :mod:`.loader` picks the frontend for each input
and merges what they produce into one Schema.
"""
