"""battgen: one IR for battery telemetry schemas (PX4 uORB, DroneCAN, devicetree, MAVLink)."""

__version__ = "0.1.0"
