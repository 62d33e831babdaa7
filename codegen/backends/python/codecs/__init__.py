"""The binary codecs of generated classes, one module or package per wire format.

- :mod:`.uorb` (with :mod:`.uorb_layout`): PX4's C-struct layout, as the logger writes it and ULog holds it;
- :mod:`.dronecan`: DSDL v0 bit streams (float16, uintN, tail-array optimisation), bit-exact with pydronecan;
- :mod:`.mavlink`: MAVLink payloads in wire order and v1/v2 frames with CRC_EXTRA.

Each is an extension of the Python backend (``extensions.Contribution``): it adds members to the
classes it applies to and names the runtime modules (``runtime/``) their packages need.
"""
