"""What a CAN capture or live bus holds (``battgen can``): nodes, types, rates, transport problems."""
