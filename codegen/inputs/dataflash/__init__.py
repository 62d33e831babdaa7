"""ArduPilot DataFlash logs: the reader (binary and text), its units and its arming rule."""
