"""DroneCAN (UAVCAN v0) and Cyphal/CAN (v1) on the wire: CAN frames from captures and live buses, reassembled
into transfers.

:mod:`.wire` holds DroneCAN's frame-level facts (the 29-bit identifier, the tail byte, the transfer CRC),
:mod:`.cyphal_wire` Cyphal/CAN's; :mod:`.reassembly` turns a stream of frames into transfers and transport
diagnostics, :mod:`.cyphal_reassembly` does it with Cyphal's rules, or for a bus carrying both;
:mod:`.cyphal_ports` tells which Cyphal type a subject carries; :mod:`.captures` reads frames from capture files
and live buses; :mod:`.records` hands the decoded transfers of one message to the data readers as records.
"""
