"""Battery failsafe parameters: files checked against ArduPilot's metadata, and proposed from a devicetree node
(``battgen params``)."""
