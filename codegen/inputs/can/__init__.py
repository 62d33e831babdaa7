"""DroneCAN (UAVCAN v0) on the wire: CAN frames from captures and live buses, reassembled into transfers.

:mod:`.wire` holds the frame-level facts (the 29-bit identifier, the tail byte, the transfer CRC);
:mod:`.reassembly` turns a stream of frames into transfers and transport diagnostics;
:mod:`.captures` reads frames from capture files and live buses; :mod:`.records` hands the decoded
transfers of one message to the data readers as records.
"""
